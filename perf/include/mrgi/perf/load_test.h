// The scheduler's load test: one suite scene replayed for `frames` frames while its
// load changes on a fixed script (keyed by frame index, so every run sees the same one):
//   - a CPU load on one core switches on and off (a thread spinning: a stand-in for thermal
//     throttling on lavapipe, whose work runs on the same cores);
//   - the virtual object leaves the view and comes back (moved out of the camera's view and
//     back: the frames where nothing virtual is seen skip the technique);
//   - a second object and a second lamp appear (scene changes at run time: declared hidden and
//     dark at start-up, shown with Runtime::set_object_visible and set_lamp) and go again.
// The scheduled run (kAutoLevel under the budget) is measured beside one run per fixed level
// under the same script: the oracle knows each frame's cost at every level and takes the best
// level that fits the budget. Frames are fed back to back with inputs preloaded (the bench's
// sustained mode). Figures exclude the first second (the controller's start).
#pragma once
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/image.h"
#include "mrgi/runtime.h"
#include "mrgi/perf/bench.h"

namespace mrgi::perf {

struct LoadTestSettings {
  std::string suite;                  // suite.json
  std::string scene = "desk_spot";    // a suite scene with a virtual object and a lamp
  std::string technique = "baseline";
  double budget_ms = 1000.0 / 30.0;
  int frames = 450;                   // 15 s at 30 fps
  int settle_frames = 30;             // excluded from the figures: the first second
  bool oracle = true;                 // also run every fixed level for the oracle
  DeviceSettings device;
  ProgressFn progress;
};

// One frame of a run.
struct LoadFrame {
  int level = 0;
  float scale = 1.0f;       // FrameStats::internal_scale
  double cost_ms = 0.0;     // FrameStats::cost_ms
  bool technique_ran = true;
};

struct LoadPhase {
  std::string what;
  int from = 0, to = 0;     // frames [from, to)
};

struct LoadTestResult {
  LoadTestSettings settings;
  std::string device;
  std::vector<LoadPhase> phases;
  std::vector<LoadFrame> scheduled;                 // the scheduled run
  std::vector<std::vector<LoadFrame>> fixed;        // per level (empty without the oracle)
  std::vector<int> oracle_level;                    // per frame (empty without the oracle)
  std::vector<std::string> level_names;
  // Figures over the frames after settle_frames.
  double share_within = 0.0;        // scheduled frames whose cost is within the budget
  double switches_per_s = 0.0;      // level changes per second of frames (at 30 fps)
  double mean_level = 0.0;          // scheduled
  double mean_oracle_level = 0.0;
  double mean_scale = 0.0;
};

Expected<LoadTestResult> run_load_test(const LoadTestSettings& settings);
std::string load_test_markdown(const LoadTestResult& r);
// level over time (scheduled and oracle), internal scale, and cost against the budget, with the
// load phases shaded.
ImageRGB8 render_load_trace(const LoadTestResult& r);

}  // namespace mrgi::perf
