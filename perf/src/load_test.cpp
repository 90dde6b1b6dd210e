// The scheduler's load test (mrgi/perf/load_test.h).
#include "mrgi/perf/load_test.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

#include "loaded_scene.h"
#include "mrgi/perf/stats.h"
#include "mrgi/perf/suite.h"

namespace mrgi::perf {
namespace {

// A thread that keeps one core busy while `on` (a stand-in for a throttled device).
class CpuLoad {
 public:
  CpuLoad() : thread_([this] { loop(); }) {}
  ~CpuLoad() {
    stop_ = true;
    thread_.join();
  }
  void set(bool on) { on_ = on; }

 private:
  void loop() {
    volatile double sink = 0.0;
    while (!stop_) {
      if (on_) {
        const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1);
        while (std::chrono::steady_clock::now() < until) sink = sink + std::sqrt(sink + 1.0);
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
  }
  std::atomic<bool> on_{false}, stop_{false};
  std::thread thread_;
};

std::vector<LoadPhase> script(int n) {
  auto at = [n](double f) { return int(std::lround(f * n)); };
  return {{"CPU load on one core", at(0.20), at(0.40)},
          {"object out of view", at(0.45), at(0.58)},
          {"second object and lamp", at(0.62), at(0.88)},
          {"CPU load on one core", at(0.72), at(0.88)}};
}

bool in(const std::vector<LoadPhase>& phases, const std::string& what, int k) {
  for (const LoadPhase& p : phases)
    if (p.what == what && k >= p.from && k < p.to) return true;
  return false;
}

bool technique_ran(const FrameStats& s) {
  for (const std::string& sk : s.skipped)
    if (sk.rfind("technique:", 0) == 0) return false;
  return true;
}

// One run of the script at `level` (kAutoLevel: scheduled).
Expected<std::vector<LoadFrame>> run_script(const LoadedScene& l, const SceneDesc& scene, const LoadTestSettings& s,
                                            const std::vector<LoadPhase>& phases, int level,
                                            std::vector<std::string>* level_names, std::string* device) {
  RuntimeSettings rs;
  rs.device = s.device;
  rs.technique = s.technique;
  rs.level = level;
  rs.frame_budget_ms = s.budget_ms;
  rs.exposure = l.info.exposure;
  const CameraSetup cameras{l.info.color, l.info.depth, l.info.depth_scale, l.info.exposure, l.info.env_camera};
  auto created = create_runtime(rs, cameras, scene);
  if (!created) return created.error();
  Runtime& rt = **created;
  if (level_names) *level_names = rt.level_names();
  if (device) *device = rt.device().name;
  const size_t second = scene.virtual_objects.size() - 1, lamp2 = scene.lights.size() - 1;
  const bool has_second_lamp = scene.lights.size() >= 2;
  MRGI_TRY(rt.set_object_visible(second, false));
  const Placement home = scene.virtual_objects[0].placement;
  Placement away = home;
  away.position.x += 50.0f;  // far outside the view and the lamps' reach of it
  LightDesc lamp_on = has_second_lamp ? scene.lights[lamp2] : LightDesc{};
  lamp_on.intensity = has_second_lamp ? scene.lights[0].intensity : 0.0f;
  LightDesc lamp_off = lamp_on;
  lamp_off.intensity = 0.0f;

  CpuLoad load;
  std::vector<LoadFrame> frames(size_t(s.frames));
  size_t got = 0;
  auto take = [&](std::vector<FrameOutput>& outs) {
    for (FrameOutput& o : outs) {
      const int64_t k = o.stats.frame_index;
      if (k >= 0 && k < s.frames) {
        frames[size_t(k)] = {o.stats.level, o.stats.internal_scale, o.stats.cost_ms, technique_ran(o.stats)};
        ++got;
      }
      rt.recycle(std::move(o));
    }
  };
  const double t_first = l.frames.front().timestamp;
  bool was_out = false, was_second = false;
  for (int k = 0; k < s.frames; ++k) {
    load.set(in(phases, "CPU load on one core", k));
    const bool out = in(phases, "object out of view", k), second_on = in(phases, "second object and lamp", k);
    if (out != was_out) MRGI_TRY(rt.set_object_placement(0, out ? away : home));
    if (second_on != was_second) {
      MRGI_TRY(rt.set_object_visible(second, second_on));
      if (has_second_lamp) MRGI_TRY(rt.set_lamp(lamp2, second_on ? lamp_on : lamp_off));
    }
    was_out = out;
    was_second = second_on;
    InputFrame f = l.frames[ping_pong(size_t(k), l.frames.size())];
    f.index = k;
    const double dt = f.depth_timestamp - f.timestamp;
    f.timestamp = t_first + double(k) * l.frame_interval_s;
    f.depth_timestamp = f.timestamp + dt;
    auto outs = rt.process(f);
    if (!outs) return outs.error();
    take(*outs);
    if (s.progress) s.progress("load test", size_t(k + 1), size_t(s.frames), 0.0);
  }
  auto rest = rt.flush();
  if (!rest) return rest.error();
  take(*rest);
  if (got != size_t(s.frames))
    return fail(ErrorKind::Internal, "load test: " + std::to_string(got) + " of " + std::to_string(s.frames) + " frames came back");
  return frames;
}

}  // namespace

Expected<LoadTestResult> run_load_test(const LoadTestSettings& s) {
  if (s.frames < 60) return fail(ErrorKind::BadUsage, "load test: --frames must be >= 60 (two seconds)");
  if (s.settle_frames < 0 || s.settle_frames >= s.frames) return fail(ErrorKind::BadUsage, "load test: settle frames 0..frames-1");
  if (!(s.budget_ms > 0.0)) return fail(ErrorKind::BadUsage, "load test: --budget-ms must be > 0");
  auto suite = load_suite(s.suite);
  if (!suite) return suite.error();
  auto picked = select_scenes(*suite, {s.scene});
  if (!picked) return picked.error();
  auto loaded = load_scene(picked->front());
  if (!loaded) return loaded.error();
  if (loaded->scene.virtual_objects.empty())
    return fail(ErrorKind::BadUsage, "load test: scene '" + s.scene + "' has no virtual object to move");
  // The scene at start-up with room for what appears later: a second copy of the first object
  // beside it and, where the scene has a lamp, a second lamp beside that one (dark).
  SceneDesc scene = loaded->scene;
  VirtualObjectDesc twin = scene.virtual_objects[0];
  twin.motion.clear();
  twin.placement.position.x += 0.25f;
  scene.virtual_objects.push_back(twin);
  if (!scene.lights.empty()) {
    LightDesc lamp = scene.lights[0];
    lamp.motion.clear();
    lamp.position.x += 0.5f;
    lamp.intensity = 0.0f;
    scene.lights.push_back(lamp);
  }
  LoadTestResult r;
  r.settings = s;
  r.phases = script(s.frames);
  auto scheduled = run_script(*loaded, scene, s, r.phases, kAutoLevel, &r.level_names, &r.device);
  if (!scheduled) return scheduled.error();
  r.scheduled = std::move(*scheduled);
  const int levels = int(r.level_names.size());
  if (s.oracle) {
    for (int lv = 0; lv < levels; ++lv) {
      auto run = run_script(*loaded, scene, s, r.phases, lv, nullptr, nullptr);
      if (!run) return run.error();
      r.fixed.push_back(std::move(*run));
    }
    for (int k = 0; k < s.frames; ++k) {
      int best = levels - 1;
      for (int lv = 0; lv < levels; ++lv)
        if (r.fixed[size_t(lv)][size_t(k)].cost_ms <= s.budget_ms) {
          best = lv;
          break;
        }
      r.oracle_level.push_back(best);
    }
  }
  size_t counted = 0, within = 0, ran = 0, switches = 0;
  double level_sum = 0.0, oracle_sum = 0.0, scale_sum = 0.0;
  for (int k = s.settle_frames; k < s.frames; ++k) {
    const LoadFrame& f = r.scheduled[size_t(k)];
    ++counted;
    within += f.cost_ms <= s.budget_ms;
    if (k > s.settle_frames && f.level != r.scheduled[size_t(k - 1)].level) ++switches;
    if (!f.technique_ran) continue;  // nothing virtual in view: no level to compare
    ++ran;
    level_sum += f.level;
    scale_sum += f.scale;
    if (!r.oracle_level.empty()) oracle_sum += r.oracle_level[size_t(k)];
  }
  r.share_within = counted ? double(within) / double(counted) : 0.0;
  r.switches_per_s = counted ? double(switches) / (double(counted) / 30.0) : 0.0;
  r.mean_level = ran ? level_sum / double(ran) : 0.0;
  r.mean_oracle_level = ran ? oracle_sum / double(ran) : 0.0;
  r.mean_scale = ran ? scale_sum / double(ran) : 0.0;
  return r;
}

std::string load_test_markdown(const LoadTestResult& r) {
  const LoadTestSettings& s = r.settings;
  std::ostringstream o;
  char buf[512];
  o << "# mrgi load test: " << s.technique << " on " << s.scene << ", budget " << s.budget_ms << " ms\n\n";
  o << "Device: " << r.device << ", " << s.frames << " frames fed back to back (inputs preloaded); the first "
    << s.settle_frames << " are the controller's start and not counted. A frame is within the budget when its cost "
       "(FrameStats::cost_ms: device time and the frame's own host work) is. The oracle takes, for each frame, the "
       "best level whose cost in its own fixed-level run of the same script was within the budget.\n\n";
  o << "| phase | frames |\n|---|---|\n";
  for (const LoadPhase& p : r.phases) o << "| " << p.what << " | " << p.from << "-" << p.to - 1 << " |\n";
  o << "\n| figure | value | target |\n|---|---:|---|\n";
  std::snprintf(buf, sizeof buf, "| frames within the budget | %.1f %% | >= 95 %% |\n", 100.0 * r.share_within);
  o << buf;
  std::snprintf(buf, sizeof buf, "| level switches per second | %.2f | <= 1 |\n", r.switches_per_s);
  o << buf;
  std::snprintf(buf, sizeof buf, "| mean level (0 = best) | %.2f | |\n", r.mean_level);
  o << buf;
  if (!r.oracle_level.empty()) {
    std::snprintf(buf, sizeof buf, "| mean oracle level | %.2f | within 1 of the scheduled |\n", r.mean_oracle_level);
    o << buf;
  }
  std::snprintf(buf, sizeof buf, "| mean internal-resolution factor | %.2f | |\n", r.mean_scale);
  o << buf;
  o << "\n![level, scale and cost over the run](trace.png)\n\nLevels: ";
  for (size_t i = 0; i < r.level_names.size(); ++i) o << (i ? ", " : "") << i << " " << r.level_names[i];
  o << ".\n";
  if (!r.fixed.empty()) {
    o << "\nFixed-level runs of the same script (median cost of the frames that ran the technique, ms):\n\n"
         "| level | median ms | within budget |\n|---|---:|---:|\n";
    for (size_t lv = 0; lv < r.fixed.size(); ++lv) {
      std::vector<double> c;
      size_t in = 0, n = 0;
      for (size_t k = size_t(s.settle_frames); k < r.fixed[lv].size(); ++k) {
        ++n;
        in += r.fixed[lv][k].cost_ms <= s.budget_ms;
        if (r.fixed[lv][k].technique_ran) c.push_back(r.fixed[lv][k].cost_ms);
      }
      std::snprintf(buf, sizeof buf, "| %zu %s | %.1f | %.1f %% |\n", lv, r.level_names[lv].c_str(), percentile(c, 50),
                    n ? 100.0 * double(in) / double(n) : 0.0);
      o << buf;
    }
  }
  return o.str();
}

}  // namespace mrgi::perf
