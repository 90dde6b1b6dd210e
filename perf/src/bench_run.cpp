// The bench loop: scenes x techniques x levels, each run preceded by a floor-pass measurement.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "gpu/context.h"
#include "gpu/floor_pass.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/sample_sheet.h"
#include "mrgi/perf/temporal.h"
#include "mrgi/perf/stats.h"
#include "mrgi/perf/suite.h"
#include "mrgi/platform/capture.h"
#include "loaded_scene.h"
#include "technique/knobs.h"

#ifndef MRGI_PERF_SOURCE_DIR
#define MRGI_PERF_SOURCE_DIR ""
#endif

namespace mrgi::perf {
namespace {

// Temporal stability over consecutive measured frames of one run (mrgi/perf/temporal.h): only
// where the output is the capture's size and the frames have depth and poses.
Status measure_stability(const LoadedScene& l, const std::vector<FrameOutput>& kept, BenchEntry& e) {
  const size_t n = l.frames.size();
  const Intrinsics& k = l.info.color;
  double sum = 0.0, truth = 0.0;
  size_t pairs = 0, truth_pairs = 0;
  for (size_t i = 1; i < kept.size(); ++i) {
    const FrameOutput& a = kept[i - 1];
    const FrameOutput& b = kept[i];
    if (b.stats.frame_index != a.stats.frame_index + 1) continue;
    const size_t sa = ping_pong(size_t(a.stats.frame_index), n), sb = ping_pong(size_t(b.stats.frame_index), n);
    const InputFrame& fa = l.frames[sa];
    const InputFrame& fb = l.frames[sb];
    if (sa == sb || !fa.pose || !fb.pose || fa.depth.empty() || fb.depth.empty()) continue;
    if (a.image.width != k.width || a.image.height != k.height || fa.color.width != k.width ||
        fa.depth.width != k.width || fa.depth.height != k.height)
      continue;
    auto view = [&](const FrameOutput& o, const InputFrame& f, size_t src) {
      StabilityFrame v;
      v.camera = &f.color;
      v.output = &o.image;
      v.reference = l.references[src] ? &*l.references[src] : nullptr;
      v.virtual_mask = o.virtual_mask.empty() ? nullptr : &o.virtual_mask;
      v.depth = &f.depth;
      v.camera_to_world = f.pose->matrix();
      return v;
    };
    auto r = delta_stability(view(a, fa, sa), view(b, fb, sb), k, l.info.depth_scale);
    if (!r.ok()) return fail(r.error().kind, "scene '" + l.suite.name + "': " + r.error().message);
    if (r->pixels == 0) continue;
    sum += r->output_change;
    ++pairs;
    if (r->has_truth) {
      truth += r->truth_change;
      ++truth_pairs;
    }
  }
  e.stability_pairs = pairs;
  e.stability = pairs > 0 ? sum / double(pairs) : 0.0;
  e.truth_stability = truth_pairs > 0 ? truth / double(truth_pairs) : -1.0;
  return ok_status();
}

std::string shell_first_line(const std::string& command) {
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buf[256];
    if (std::fgets(buf, sizeof buf, p)) out = buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// Resolves the --levels items for one technique into level indices, best first.

TimeSummary summarize(const std::vector<double>& ms, double floor_ms, double floor_min_ms) {
  TimeSummary t;
  t.samples = ms.size();
  t.median_ms = percentile(ms, 50);
  t.p95_ms = percentile(ms, 95);
  t.min_ms = ms.empty() ? 0.0 : *std::min_element(ms.begin(), ms.end());
  if (floor_ms > 0.0) {
    t.median_ratio = t.median_ms / floor_ms;
    t.p95_ratio = t.p95_ms / floor_ms;
  }
  if (floor_min_ms > 0.0) t.min_ratio = t.min_ms / floor_min_ms;
  return t;
}

// Raw samples of one run, summarized once the scene's floor is known.
struct RunSamples {
  BenchEntry entry;
  std::vector<double> interval_ms;   // sustained phase: completion to completion
  double sustained_ms = 0.0;         // sustained phase: wall clock over the measured frames / frames
  double cpu_ms = 0.0;               // sustained phase: process CPU time over the same interval / frames
  std::vector<double> profiled_ms;   // profiling phase: sum of the passes per frame
  std::vector<std::string> pass_order;
  std::map<std::string, std::vector<double>> pass_ms, pass_cpu_ms;
};

struct Progress {
  const ProgressFn* fn = nullptr;
  size_t done = 0, total = 0;
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  void step(const std::string& what, size_t frames) {
    done += frames;
    if (fn && *fn)
      (*fn)(what, done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
};

// The per-pass split's row for the host's own work on a frame (FrameStats::host_ms).
const char* const kHostPassName = "host_record_upload_readback";

Expected<RunSamples> run_one(const LoadedScene& l, const std::string& technique, int level,
                             const BenchSettings& s, const std::string& floor_device, gpu::FloorTimer& floor,
                             std::vector<double>& floor_ms) {
  RuntimeSettings rs;
  rs.device = s.device;
  rs.residual_light = s.residual_light;
  if (s.specular_ablation.any()) {
    auto research = std::make_shared<ResearchSettings>();
    research->specular = s.specular_ablation;
    rs.research = research;
  }
  rs.knobs = s.knobs;
  rs.frames_in_flight = s.frames_in_flight;
  rs.technique = technique;
  rs.level = level;
  rs.exposure = l.info.exposure;
  rs.output_width = s.width;
  rs.output_height = s.height;
  const CameraSetup cameras{l.info.color, l.info.depth, l.info.depth_scale, l.info.exposure, l.info.env_camera};
  auto created = create_runtime(rs, cameras, l.scene);
  const std::string what = "scene '" + l.suite.name + "', technique '" + technique + "', level " + std::to_string(level);
  if (!created.ok()) return fail(created.error().kind, what + ": " + created.error().message);
  std::unique_ptr<Runtime> rt = std::move(created).value();
  if (rt->device().name != floor_device)
    return fail(ErrorKind::Device, what + ": the runtime chose device '" + rt->device().name +
                                       "' but the floor pass ran on '" + floor_device + "'; ratios would compare devices");

  RunSamples r;
  BenchEntry& e = r.entry;
  e.scene = l.suite.name;
  e.set = l.suite.set;
  e.technique = technique;
  e.level = level;
  const auto level_names = rt->level_names();
  e.level_name = level < int(level_names.size()) ? level_names[size_t(level)] : std::to_string(level);
  e.width = s.width ? s.width : l.info.color.width;
  e.height = s.height ? s.height : l.info.color.height;
  e.memory_mib = rt->memory_mib();
  std::set<std::string> skipped;
  const size_t warmup = size_t(s.warmup), measured = size_t(s.frames);
  const size_t total = warmup + measured, profiled_total = total + size_t(s.profile_frames), n = l.frames.size();
  const std::vector<InputFrame> run_frames = preload_run(l, profiled_total);

  // Phase 1, sustained: frames fed back to back with frames_in_flight in flight, as a live
  // device runs; the outputs are kept and measured afterwards, so no host work of the bench
  // competes with the frames for the CPU. The interval is from the completion of the last
  // warm-up frame to that of the last measured one. Each output is copied into storage touched
  // before the loop and handed back (Runtime::recycle) as a live loop would, so no frame pays
  // for fresh pages (runtime.h says what they cost); the copy, about 0.2 ms, stays in.
  std::vector<FrameOutput> kept(measured);
  for (FrameOutput& f : kept) {
    f.image = ImageRGBA8(e.width, e.height);
    f.virtual_mask = Image<uint8_t, 1>(e.width, e.height);
  }
  size_t kept_count = 0;
  double start_s = -1.0, end_s = -1.0;
  double start_cpu_ms = -1.0;
  auto keep = [&](std::vector<FrameOutput>& outs) -> Status {
    for (FrameOutput& out : outs) {
      const int64_t k = out.stats.frame_index;
      if (k < 0 || size_t(k) >= total)
        return fail(ErrorKind::Internal, what + ": runtime returned frame index " + std::to_string(k) +
                                             " outside 0.." + std::to_string(total - 1));
      if (warmup > 0 && size_t(k) + 1 == warmup) {
        start_s = out.stats.completed_s;
        start_cpu_ms = gpu::process_cpu_ms();
      }
      if (size_t(k) < warmup) continue;
      if (kept_count >= measured)
        return fail(ErrorKind::Internal, what + ": more measured frames came back than were run");
      const double previous = kept_count == 0 ? start_s : kept[kept_count - 1].stats.completed_s;
      if (previous >= 0.0) r.interval_ms.push_back(1000.0 * (out.stats.completed_s - previous));
      if (size_t(k) + 1 == total) end_s = out.stats.completed_s;
      for (const std::string& sk : out.stats.skipped) skipped.insert(sk);
      FrameOutput& dst = kept[kept_count++];
      const auto copy_into = [](auto& to, auto& from) {
        if (to.data.size() == from.data.size() && to.width == from.width)
          std::copy(from.data.begin(), from.data.end(), to.data.begin());
        else
          to = std::move(from);
      };
      copy_into(dst.image, out.image);
      copy_into(dst.virtual_mask, out.virtual_mask);
      dst.stats = std::move(out.stats);
      dst.light = std::move(out.light);
      rt->recycle(std::move(out));
    }
    for (FrameOutput& out : outs)
      if (!out.image.empty()) rt->recycle(std::move(out));  // warm-up frames
    return ok_status();
  };
  const auto loop_start = std::chrono::steady_clock::now();
  const double loop_start_cpu_ms = gpu::process_cpu_ms();
  for (size_t k = 0; k < total; ++k) {
    auto outs = rt->process(run_frames[k]);
    if (!outs.ok()) return fail(outs.error().kind, what + ", frame " + std::to_string(k) + ": " + outs.error().message);
    MRGI_TRY(keep(*outs));
  }
  auto rest = rt->flush();
  if (!rest.ok()) return fail(rest.error().kind, what + ", flush: " + rest.error().message);
  MRGI_TRY(keep(*rest));
  const double end_cpu_ms = gpu::process_cpu_ms();
  if (kept_count != measured)
    return fail(ErrorKind::Internal, what + ": " + std::to_string(kept_count) + " of " + std::to_string(measured) +
                                         " measured frames came back");
  if (start_s < 0.0)  // no warm-up: from the first call (includes filling the pipeline)
    start_s = std::chrono::duration<double>(loop_start.time_since_epoch()).count();
  r.sustained_ms = 1000.0 * (end_s - start_s) / double(measured);
  // The CPU clock is read when the host sees the completions (the first after the warm-up, the
  // flush after the last), so it spans the same frames as the wall clock above.
  r.cpu_ms = (end_cpu_ms - (start_cpu_ms >= 0.0 ? start_cpu_ms : loop_start_cpu_ms)) / double(measured);

  bool pooled_any = false;
  const FrameOutput* sampled = nullptr;  // the last measured frame with a reference
  for (const FrameOutput& out : kept) {
    const size_t src = ping_pong(size_t(out.stats.frame_index), n);
    if (!l.references[src]) continue;
    sampled = &out;
    // At another output size (--width/--height, --sizes) camera, reference and mask are resampled
    // to it, as `mrgi replay` does.
    const int w = out.image.width, h = out.image.height;
    const ImageRGB8 camera = resize_bilinear(l.frames[src].color, w, h);
    const ImageRGB8 reference = resize_bilinear(*l.references[src], w, h);
    std::optional<ImageU8> mask_resized;
    if (l.masks[src]) mask_resized = resize_nearest(*l.masks[src], w, h);
    const ImageU8* mask = mask_resized ? &*mask_resized : nullptr;
    auto err = measure_error(out.image, camera, reference, mask);
    if (!err.ok()) return fail(err.error().kind, what + ", frame " + std::to_string(src) + ": " + err.error().message);
    if (!pooled_any) {
      e.error = *err;
    } else {
      e.error = pool(e.error, *err);
    }
    pooled_any = true;
  }
  e.has_reference = pooled_any;
  if (sampled) {
    e.sample = thumbnail(sampled->image, kSampleWidth);
    e.sample_frame = int(ping_pong(size_t(sampled->stats.frame_index), n));
  }
  MRGI_TRY(measure_stability(l, kept, e));
  kept.clear();

  // Phase 2, profiling mode: the same runtime, warm, each pass submitted alone and host-timed,
  // so the split adds up; floor samples between its frames track the machine's load.
  if (s.profile_frames > 0) {
    MRGI_TRY(rt->set_profiling(true));
    auto take = [&](std::vector<FrameOutput>& outs) {
      for (const FrameOutput& out : outs) {
        if (size_t(out.stats.frame_index) < total) continue;  // sustained frames still in flight
        // The frame = its passes + the host's own work on it (record, upload, readback), which
        // on a CPU device takes the same cores the passes run on.
        r.profiled_ms.push_back(out.stats.gpu_total_ms + out.stats.host_ms);
        auto add = [&](const std::string& name, double ms, double cpu_ms) {
          auto [it, inserted] = r.pass_ms.try_emplace(name);
          if (inserted) r.pass_order.push_back(name);
          it->second.push_back(ms);
          r.pass_cpu_ms[name].push_back(cpu_ms);
        };
        for (const PassTiming& p : out.stats.passes) add(p.name, p.gpu_ms, p.cpu_ms);
        add(kHostPassName, out.stats.host_ms, out.stats.host_ms);  // the host thread's own
      }
      for (FrameOutput& out : outs) rt->recycle(std::move(out));
    };
    for (size_t k = total; k < profiled_total; ++k) {
      auto outs = rt->process(run_frames[k]);
      if (!outs.ok()) return fail(outs.error().kind, what + ", profiled frame " + std::to_string(k) + ": " + outs.error().message);
      take(*outs);
      auto st = floor.sample(uint32_t(s.floor_per_frame), floor_ms);
      if (!st.ok()) return fail(st.error().kind, what + ": floor pass: " + st.error().message);
    }
    auto tail = rt->flush();
    if (!tail.ok()) return fail(tail.error().kind, what + ", flush: " + tail.error().message);
    take(*tail);
  }
  e.skipped.assign(skipped.begin(), skipped.end());
  return r;
}

}  // namespace

Expected<std::vector<int>> resolve_levels(const std::string& technique, const std::vector<std::string>& items) {
  auto names = technique_levels(technique);
  if (!names.ok()) return names.error();
  const int n = int(names->size());
  if (n == 0) return fail(ErrorKind::Internal, "technique '" + technique + "' declares no quality levels");
  std::set<int> picked;
  const bool all = items.empty() || (items.size() == 1 && items[0] == "all");
  for (int i = 0; all && i < n; ++i) picked.insert(i);
  for (size_t k = 0; !all && k < items.size(); ++k) {
    const std::string& it = items[k];
    int index = -1;
    if (it == "last") index = n - 1;
    for (int i = 0; i < n && index < 0; ++i)
      if ((*names)[i] == it) index = i;
    if (index < 0 && !it.empty() && it.find_first_not_of("0123456789") == std::string::npos) {
      const long v = std::strtol(it.c_str(), nullptr, 10);
      if (v < n) index = int(v);
    }
    if (index < 0) {
      std::string known;
      for (int i = 0; i < n; ++i) known += (i ? ", " : "") + std::to_string(i) + "=" + (*names)[i];
      return fail(ErrorKind::BadUsage, "--levels '" + it + "': technique '" + technique + "' has levels " + known +
                                           " (or 'last', 'all')");
    }
    picked.insert(index);
  }
  return std::vector<int>(picked.begin(), picked.end());
}

std::string ensure_lp_num_threads() {
  setenv("LP_NUM_THREADS", "2", /*overwrite=*/0);
  const char* v = std::getenv("LP_NUM_THREADS");
  return v ? v : "";
}

Expected<BenchResult> run_bench(const BenchSettings& s) {
  if (s.frames < 1) return fail(ErrorKind::BadUsage, "--frames must be at least 1 (got " + std::to_string(s.frames) + ")");
  if (s.warmup < 0) return fail(ErrorKind::BadUsage, "--warmup must not be negative");
  if (s.profile_frames < 0) return fail(ErrorKind::BadUsage, "--profile-frames must not be negative");
  if (s.frames_in_flight < 1 || s.frames_in_flight > 3)
    return fail(ErrorKind::BadUsage, "frames_in_flight must be 1..3");
  if ((s.width == 0) != (s.height == 0) || s.width < 0 || s.height < 0)
    return fail(ErrorKind::BadUsage, "--width and --height go together (both 0 = each capture's size)");
  if (s.floor_frames < 3) return fail(ErrorKind::BadUsage, "floor_frames must be at least 3");
  if (s.floor_warmup < 0 || s.floor_per_frame < 0)
    return fail(ErrorKind::BadUsage, "floor_warmup and floor_per_frame must not be negative");

  BenchResult result;
  result.lp_num_threads = ensure_lp_num_threads();
  result.started_utc = utc_now();
  result.suite = s.suite;
  result.frames = s.frames;
  result.warmup = s.warmup;
  result.subset = !s.scenes.empty() || !s.techniques.empty() ||
                  !(s.levels.empty() || (s.levels.size() == 1 && s.levels[0] == "all"));
  const std::string src_dir = MRGI_PERF_SOURCE_DIR;
  if (!src_dir.empty()) {
    result.commit = shell_first_line("git -C '" + src_dir + "' rev-parse HEAD 2>/dev/null");
    result.dirty = !result.commit.empty() &&
                   !shell_first_line("git -C '" + src_dir + "' status --porcelain --untracked-files=no 2>/dev/null").empty();
  }

  auto suite = load_suites(s.suite);
  if (!suite.ok()) return suite.error();
  auto scenes = select_scenes(*suite, s.scenes);
  if (!scenes.ok()) return scenes.error();

  std::vector<std::string> techniques = s.techniques.empty() ? technique_names() : s.techniques;
  const std::vector<std::string> known = technique_names();
  std::vector<std::pair<std::string, std::vector<int>>> plan;
  for (const std::string& t : techniques) {
    if (std::find(known.begin(), known.end(), t) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      return fail(ErrorKind::BadUsage, "--techniques: unknown technique '" + t + "' (registered: " + list + ")");
    }
    auto levels = resolve_levels(t, s.levels);
    if (!levels.ok()) return levels.error();
    plan.emplace_back(t, std::move(levels).value());
  }
  if (plan.empty()) return fail(ErrorKind::BadUsage, "no technique to run (the registry is empty)");

  auto floor_ctx = gpu::Context::create(s.device);
  if (!floor_ctx.ok()) return fail(floor_ctx.error().kind, "floor pass: " + floor_ctx.error().message);
  gpu::Context& ctx = **floor_ctx;
  result.device = ctx.info().name;
  result.driver = ctx.info().driver;

  Progress progress;
  progress.fn = &s.progress;
  size_t runs_per_scene = 0;
  for (const auto& [t, levels] : plan) runs_per_scene += levels.size();
  progress.total = scenes->size() * runs_per_scene * size_t(s.warmup + s.frames + s.profile_frames);
  const auto t0 = std::chrono::steady_clock::now();

  // The sweep's combinations (one, empty, without a sweep), each the knobs it adds and its label.
  struct Combination {
    std::vector<KnobSetting> knobs;
    std::string label;
  };
  std::vector<Combination> combinations(1);
  for (const auto& [name, values] : s.sweeps) {
    if (values.empty()) return fail(ErrorKind::BadUsage, "--sweep " + name + ": no values");
    std::vector<Combination> next;
    for (const Combination& c : combinations)
      for (double v : values) {
        Combination d = c;
        d.knobs.push_back({name, v});
        d.label += " " + name + "=" + technique::knob_number(v);
        next.push_back(std::move(d));
      }
    combinations = std::move(next);
  }
  if (!s.sweeps.empty()) {
    progress.total *= combinations.size();
    for (const auto& [t, levels] : plan)
      for (const Combination& c : combinations) {
        std::vector<KnobSetting> knobs = s.knobs;
        knobs.insert(knobs.end(), c.knobs.begin(), c.knobs.end());
        auto ladder = technique_ladder(t, knobs);  // refused before any scene runs
        if (!ladder.ok()) return fail(ladder.error().kind, "--sweep" + c.label + ": " + ladder.error().message);
      }
  }

  std::vector<double> all_floor;
  for (const SuiteScene& sc : *scenes) {
    auto loaded = load_scene(sc);
    if (!loaded.ok()) return loaded.error();
    const int w = loaded->info.color.width, h = loaded->info.color.height;
    std::vector<double> floor_ms;
    std::vector<RunSamples> runs;
    auto floor = gpu::FloorTimer::create(ctx, uint32_t(w), uint32_t(h), uint32_t(s.floor_warmup));
    if (!floor.ok()) return fail(floor.error().kind, "floor pass (scene '" + sc.name + "'): " + floor.error().message);
    for (const auto& [t, levels] : plan)
      for (size_t ci = 0; ci < combinations.size(); ++ci)
      for (int level : levels) {
        // Floor samples before each run and between its frames: machine load drifts, and a
        // scene's ratios should divide by floor times taken alongside its own.
        auto st = floor->sample(uint32_t(s.floor_frames), floor_ms);
        if (!st.ok()) return fail(st.error().kind, "floor pass (scene '" + sc.name + "'): " + st.error().message);
        BenchSettings with = s;
        with.knobs.insert(with.knobs.end(), combinations[ci].knobs.begin(), combinations[ci].knobs.end());
        auto run = run_one(*loaded, t, level, with, result.device, *floor, floor_ms);
        if (!run.ok()) return run.error();
        if (!s.sweeps.empty()) {
          run->entry.level_name += combinations[ci].label;
          run->entry.level += 1000 * int(ci + 1);
        }
        runs.push_back(std::move(run).value());
        progress.step(sc.name + " " + t + " " + runs.back().entry.level_name,
                      size_t(s.warmup + s.frames + s.profile_frames));
      }
    // A floor sample of 0 ms (or less) is the timestamp query failing, not a pass that took no
    // time (seen under heavy load on lavapipe): such samples are dropped, and only a scene with
    // none left fails, instead of every scene's runs being lost to one bad sample set.
    const size_t taken = floor_ms.size();
    if (const size_t dropped = drop_unresolved_times(floor_ms))
      std::fprintf(stderr, "bench: scene '%s': %zu of %zu floor-pass samples read 0 ms (timestamps not resolved) and were dropped\n",
                   sc.name.c_str(), dropped, taken);
    SceneFloor f;
    f.scene = sc.name;
    f.width = w;
    f.height = h;
    f.samples = floor_ms.size();
    f.median_ms = percentile(floor_ms, 50);
    f.p95_ms = percentile(floor_ms, 95);
    f.min_ms = floor_ms.empty() ? 0.0 : *std::min_element(floor_ms.begin(), floor_ms.end());
    if (!(f.median_ms > 0.0))
      return fail(ErrorKind::Device, "floor pass (scene '" + sc.name + "'): none of its " + std::to_string(taken) +
                                         " GPU times was above 0 ms; the device's timestamps are unusable for ratios");
    all_floor.insert(all_floor.end(), floor_ms.begin(), floor_ms.end());
    result.floors.push_back(f);
    for (RunSamples& r : runs) {
      r.entry.frame = summarize(r.interval_ms, f.median_ms, f.min_ms);
      r.entry.sustained_ms = r.sustained_ms;
      r.entry.sustained_ratio = r.sustained_ms / f.median_ms;
      r.entry.cpu_ms = r.cpu_ms;
      r.entry.profiled = summarize(r.profiled_ms, f.median_ms, f.min_ms);
      for (const std::string& name : r.pass_order)
        r.entry.passes.push_back(PassSummary{name, summarize(r.pass_ms[name], f.median_ms, f.min_ms),
                                             percentile(r.pass_cpu_ms[name], 50)});
      const int frame = r.entry.sample_frame;
      const bool have = std::any_of(result.samples.begin(), result.samples.end(), [&](const SceneSample& x) {
        return x.scene == sc.name && x.frame == frame;
      });
      if (frame >= 0 && !have && loaded->references[size_t(frame)])
        result.samples.push_back(SceneSample{sc.name, frame, thumbnail(loaded->frames[size_t(frame)].color, kSampleWidth),
                                             thumbnail(*loaded->references[size_t(frame)], kSampleWidth)});
      result.entries.push_back(std::move(r.entry));
    }
  }
  result.floor_median_ms = percentile(all_floor, 50);
  result.duration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

std::vector<LevelAggregate> aggregate_levels(const BenchResult& result) {
  std::vector<LevelAggregate> out;
  for (const BenchEntry& e : result.entries) {
    auto it = std::find_if(out.begin(), out.end(), [&](const LevelAggregate& a) {
      return a.technique == e.technique && a.level == e.level;
    });
    if (it == out.end()) {
      out.push_back(LevelAggregate{e.technique, e.level_name, e.level});
      it = out.end() - 1;
    }
    it->scenes += 1;
    it->mean_median_ms += e.sustained_ms;
    it->mean_median_ratio += e.sustained_ratio;
    it->mean_cpu_ms += e.cpu_ms;
    it->max_memory_mib = std::max(it->max_memory_mib, e.memory_mib);
    if (e.has_reference) {
      if (!it->has_reference) {
        it->error = e.error;
      } else {
        it->error = pool(it->error, e.error);
      }
      it->has_reference = true;
    }
  }
  for (LevelAggregate& a : out) {
    a.mean_median_ms /= double(a.scenes);
    a.mean_median_ratio /= double(a.scenes);
    a.mean_cpu_ms /= double(a.scenes);
  }
  return out;
}

}  // namespace mrgi::perf
