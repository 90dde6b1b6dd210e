// `mrgi bench --serve`: one build's side of an A/B comparison (mrgi/perf/ab_compare.h has the
// protocol). Keeps the captures loaded, so the two builds' measurements can alternate closely.
#include <algorithm>
#include <chrono>
#include <istream>
#include <map>
#include <memory>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "gpu/frame_graph.h"
#include "loaded_scene.h"
#include "mrgi/perf/ab_compare.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/stats.h"
#include "mrgi/perf/suite.h"
#include "mrgi/runtime.h"

#ifndef MRGI_PERF_SOURCE_DIR
#define MRGI_PERF_SOURCE_DIR ""
#endif

namespace mrgi::perf {
namespace {

using nlohmann::json;

// The runtime of the entry being measured.
struct WorkerEntry {
  std::string key;  // suite|scene|technique|level
  const LoadedScene* scene = nullptr;
  std::unique_ptr<Runtime> runtime;
  std::string level_name;
  bool scheduled = false;  // level "auto": the scheduler chooses
  size_t next_frame = 0;  // frames fed so far: the next run continues the capture's timeline
};

// The one level an entry names (an index, a name or "last").
Expected<int> level_index(const std::string& technique, const std::string& level) {
  auto levels = resolve_levels(technique, {level});
  if (!levels.ok()) return levels.error();
  if (levels->size() != 1) return fail(ErrorKind::BadUsage, "level '" + level + "': name one level of '" + technique + "'");
  return levels->front();
}

// W + F frames back to back, then P in profiling mode, on the entry's runtime.
Expected<json> measure(WorkerEntry& e, int frames, int warmup, int profile_frames) {
  Runtime& rt = *e.runtime;
  const size_t total = size_t(warmup + frames), count = total + size_t(profile_frames);
  const std::vector<InputFrame> run = preload_run(*e.scene, count, e.next_frame);
  e.next_frame += count;
  size_t seen = 0, within = 0;
  double start_s = -1.0, end_s = -1.0, start_cpu = -1.0, level_sum = 0.0;
  auto take = [&](std::vector<FrameOutput>& outs) {
    for (FrameOutput& out : outs) {
      ++seen;
      if (seen == size_t(warmup)) {
        start_s = out.stats.completed_s;
        start_cpu = gpu::process_cpu_ms();
      }
      if (seen > size_t(warmup) && seen <= total) {  // the sustained frames: the scheduler's figures
        within += out.stats.cost_ms <= out.stats.budget_ms ? 1 : 0;
        level_sum += out.stats.level;
      }
      if (seen == total) end_s = out.stats.completed_s;
      rt.recycle(std::move(out));
    }
  };
  const double loop_cpu = gpu::process_cpu_ms();
  const auto loop_start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < total; ++k) {
    auto outs = rt.process(run[k]);
    if (!outs.ok()) return outs.error();
    take(*outs);
  }
  auto rest = rt.flush();
  if (!rest.ok()) return rest.error();
  take(*rest);
  const double end_cpu = gpu::process_cpu_ms();
  if (seen != total || end_s < 0.0)
    return fail(ErrorKind::Internal, std::to_string(seen) + " of " + std::to_string(total) + " frames came back");
  if (start_s < 0.0) start_s = std::chrono::duration<double>(loop_start.time_since_epoch()).count();
  json answer = {{"ok", true},
                 {"level_name", e.level_name},
                 {"device", rt.device().name},
                 {"sustained_ms", 1000.0 * (end_s - start_s) / double(frames)},
                 {"cpu_ms", (end_cpu - (start_cpu >= 0.0 ? start_cpu : loop_cpu)) / double(frames)}};
  if (e.scheduled) {
    answer["budget_frames"] = frames;
    answer["within_budget_frames"] = within;
    answer["mean_level"] = level_sum / double(frames);
  }
  if (profile_frames > 0) {
    MRGI_TRY(rt.set_profiling(true));
    std::map<std::string, std::vector<double>> passes;
    std::vector<double> profiled;
    auto profile = [&](std::vector<FrameOutput>& outs) {
      for (FrameOutput& out : outs) {
        profiled.push_back(out.stats.gpu_total_ms + out.stats.host_ms);
        for (const PassTiming& p : out.stats.passes) passes[p.name].push_back(p.gpu_ms);
        passes["host_record_upload_readback"].push_back(out.stats.host_ms);
        rt.recycle(std::move(out));
      }
    };
    for (size_t k = total; k < count; ++k) {
      auto outs = rt.process(run[k]);
      if (!outs.ok()) return outs.error();
      profile(*outs);
    }
    auto tail = rt.flush();
    if (!tail.ok()) return tail.error();
    profile(*tail);
    MRGI_TRY(rt.set_profiling(false));
    // Each pass's fastest frame: load from other processes only ever adds time, so the minimum
    // is the figure least moved by it (the median is answered too, for the report).
    json p = json::object(), fastest = json::object();
    for (auto& [name, ms] : passes) {
      p[name] = median(ms);
      fastest[name] = *std::min_element(ms.begin(), ms.end());
    }
    answer["profiled_ms"] = median(profiled);
    answer["passes"] = p;
    answer["passes_min"] = fastest;
  }
  return answer;
}

Expected<json> handle(const json& req, std::map<std::string, LoadedScene>& scenes, WorkerEntry& current,
                      const std::string& device) {
  const std::string suite_path = req.at("suite").get<std::string>(), scene = req.at("scene").get<std::string>();
  const std::string technique = req.at("technique").get<std::string>(), level = req.at("level").get<std::string>();
  const int frames = req.value("frames", 8), warmup = req.value("warmup", 2), profile = req.value("profile_frames", 0);
  if (frames < 1 || warmup < 0 || profile < 0) return fail(ErrorKind::BadUsage, "frames >= 1, warmup and profile_frames >= 0");
  const std::string scene_key = suite_path + "|" + scene;
  auto loaded = scenes.find(scene_key);
  if (loaded == scenes.end()) {
    auto suite = load_suites(suite_path);
    if (!suite.ok()) return suite.error();
    auto picked = select_scenes(*suite, {scene});
    if (!picked.ok()) return picked.error();
    auto l = load_scene(picked->front());
    if (!l.ok()) return l.error();
    loaded = scenes.emplace(scene_key, std::move(l).value()).first;
  }
  const std::string key = scene_key + "|" + technique + "|" + level;
  // A fresh runtime for every measurement unless asked to keep it: a technique whose frames read
  // back earlier frames' results (dir's) settles into a state that depends on which frame
  // completed first, and two workers kept on one runtime each diverged for good (corner/dir/fast:
  // shade_direct 30 % apart over 12 pairs of identical builds); fresh, every measurement of
  // both starts alike.
  if (current.key != key || !current.runtime || req.value("fresh", true)) {
    current = WorkerEntry{};
    const bool scheduled = level == "auto";
    auto index = scheduled ? Expected<int>(kAutoLevel) : level_index(technique, level);
    if (!index.ok()) return index.error();
    const LoadedScene& l = loaded->second;
    RuntimeSettings rs;
    rs.device.device = device;
    rs.technique = technique;
    rs.level = *index;
    rs.exposure = l.info.exposure;
    const CameraSetup cameras{l.info.color, l.info.depth, l.info.depth_scale, l.info.exposure, l.info.env_camera};
    auto rt = create_runtime(rs, cameras, l.scene);
    if (!rt.ok()) return rt.error();
    current.runtime = std::move(rt).value();
    current.key = key;
    current.scene = &l;
    current.scheduled = scheduled;
    const auto names = current.runtime->level_names();
    current.level_name = !scheduled && size_t(*index) < names.size() ? names[size_t(*index)] : level;
  }
  return measure(current, frames, warmup, profile);
}

}  // namespace

int serve_bench_worker(std::istream& in, std::ostream& out, const std::string& device) {
  ensure_lp_num_threads();
  const std::string src_dir = MRGI_PERF_SOURCE_DIR;
  out << json{{"ok", true}, {"protocol", 1}, {"source", src_dir}}.dump() << std::endl;
  std::map<std::string, LoadedScene> scenes;
  WorkerEntry current;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    json answer;
    try {
      const json req = json::parse(line);
      const std::string op = req.value("op", "");
      if (op == "quit") return 0;
      if (op != "measure") {
        answer = {{"ok", false}, {"error", "unknown op '" + op + "' (measure, quit)"}};
      } else {
        auto r = handle(req, scenes, current, device);
        answer = r.ok() ? *r : json{{"ok", false}, {"error", r.error().message}};
      }
    } catch (const std::exception& e) {
      answer = {{"ok", false}, {"error", std::string("bad request: ") + e.what()}};
    }
    out << answer.dump() << std::endl;
  }
  return 0;
}

}  // namespace mrgi::perf
