// The bench: replays the scene suite through every technique and quality level on one Vulkan
// device, times a floor pass in the same process, and measures error against the captures'
// references.
//
// One run (scene, technique, level) = a fresh Runtime at that level, in two phases:
//  1. sustained: `warmup` frames then `frames` measured ones fed back to back with
//     frames_in_flight in flight and every input preloaded (what a live device sees). The
//     headline, sustained_ms, is the wall clock from the completion of the last warm-up frame
//     to that of the last measured one, over `frames`. RDE is measured on these frames' outputs
//     after the phase, so the bench's own host work never competes with a timed frame.
//  2. profiling: `profile_frames` more frames in the runtime's profiling mode (each pass
//     submitted alone and host-timed), which gives the per-pass split that adds up; its frame
//     total (profiled) is compared with sustained_ms in the report.
// A capture shorter than the run is replayed forth and back (0,1,..,n-1,n-2,..,1,0,1,..) with
// timestamps continued, so the motion stays continuous for temporal filters. The floor pass is
// timed at the output size before every run and after every profiled frame; a scene's floor is
// the median of all its floor samples, so ratios compare times taken in the same process under
// the same machine load.
#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/metrics.h"
#include "mrgi/research.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {

// what, done, total, elapsed seconds (units: frames, warm-up included).
using ProgressFn = std::function<void(const std::string&, size_t, size_t, double)>;

struct BenchSettings {
  std::string suite;                     // path of suite.json; several, comma-separated, run as one
  std::vector<std::string> scenes;       // empty = every scene of the suite
  std::vector<std::string> techniques;   // empty = technique_names()
  // Empty or {"all"} = every level; else level indices ("0"), names, or "last" (the cheapest).
  std::vector<std::string> levels;
  int frames = 16;                       // measured frames per run (>= 1)
  int warmup = 4;                        // frames per run before measuring (>= 0)
  int profile_frames = 8;                // profiling-mode frames per run for the split (>= 0)
  int frames_in_flight = 2;              // sustained phase, as a live device runs (1..3)
  int width = 0, height = 0;             // output size; 0 = each capture's colour size
  int floor_frames = 10;                 // floor pass samples before each run (>= 3)
  int floor_per_frame = 2;               // floor pass samples after each measured frame (>= 0)
  int floor_warmup = 3;                  // unmeasured floor frames per scene
  DeviceSettings device;
  bool residual_light = true;            // RuntimeSettings::residual_light
  SpecularAblation specular_ablation;    // ResearchSettings::specular (mrgi/research.h, an ablation)
  std::vector<KnobSetting> knobs;        // RuntimeSettings::knobs (one technique only)
  // Knob sweeps (one technique only): every combination of the values is run at every chosen
  // level, on top of `knobs`; an entry's level_name then names its values ("high volume_cells=32
  // diffuse_cones=5") and its level is 1000 x (combination + 1) + the level index, so the
  // report, the aggregate and the plot keep the combinations apart. Empty: no sweep.
  std::vector<std::pair<std::string, std::vector<double>>> sweeps;
  ProgressFn progress;                   // optional
};

// Times of one series (frame total or one pass), in ms and as ratios to the scene's floor.
struct TimeSummary {
  size_t samples = 0;
  double median_ms = 0.0, p95_ms = 0.0;
  double median_ratio = 0.0, p95_ratio = 0.0;  // ms / the scene's floor median ms
  // The fastest sample, over the fastest floor sample: load on a shared machine only ever adds
  // time, so the minima move least between runs (the per-pass regression rule compares them).
  double min_ms = 0.0, min_ratio = 0.0;
};

struct PassSummary {
  std::string name;
  TimeSummary time;  // profiling phase: over the frames in which the pass ran (samples says how many)
  double cpu_median_ms = 0.0;  // profiling phase: median process CPU time (PassTiming::cpu_ms)
};

struct BenchEntry {
  std::string scene, technique, level_name;
  std::string set;                       // the scene's manifest (SuiteScene::set)
  int level = 0;
  int width = 0, height = 0;             // output size
  // The headline: wall-clock ms per frame sustained over the measured frames (phase 1), and
  // its ratio to the scene's floor.
  double sustained_ms = 0.0, sustained_ratio = 0.0;
  // CPU time of the whole process (the host thread and the driver's worker threads) over the
  // same interval, per measured frame. On a shared machine it moves less than wall time with
  // other tenants' load (time the machine gives elsewhere is not counted), so it is the figure
  // to compare two builds by; on lavapipe it approaches LP_NUM_THREADS x the work's wall time.
  double cpu_ms = 0.0;
  TimeSummary frame;                     // phase 1: intervals between frame completions
  TimeSummary profiled;                  // phase 2: per frame, the sum of its passes
  std::vector<PassSummary> passes;       // in first-seen order
  double memory_mib = 0.0;               // Runtime::memory_mib()
  bool has_reference = false;            // error below is meaningful only when true
  RdeReport error;                       // pooled over the measured frames
  std::vector<std::string> skipped;      // distinct skip notes seen over the measured frames
  // Temporal stability (mrgi/perf/temporal.h): the mean over consecutive measured frame pairs
  // of the frame-to-frame change of the delta on static real pixels, linear, and the truth's;
  // stability_pairs 0 = not measured (no depth or poses, another output size, one frame),
  // truth_stability < 0 = no references.
  size_t stability_pairs = 0;
  double stability = 0.0, truth_stability = -1.0;
  // The last measured frame that has a reference, kSampleWidth wide (mrgi/perf/sample_sheet.h),
  // and its frame in the capture; -1 = none kept (no references).
  ImageRGB8 sample;
  int sample_frame = -1;
};

// The camera frame and the reference of a scene's sampled frame, kSampleWidth wide.
struct SceneSample {
  std::string scene;
  int frame = 0;
  ImageRGB8 camera, reference;
};

struct SceneFloor {
  std::string scene;
  int width = 0, height = 0;
  size_t samples = 0;
  double median_ms = 0.0, p95_ms = 0.0, min_ms = 0.0;
};

struct BenchResult {
  std::vector<BenchEntry> entries;       // scene-major, then technique, then level
  std::vector<SceneFloor> floors;        // one per scene
  std::vector<SceneSample> samples;      // the inputs of the entries' samples, one per scene and frame
  double floor_median_ms = 0.0;          // over every floor sample of the run
  std::string device, driver;
  std::string lp_num_threads;            // the value in effect ("" = unset: not a valid timing)
  std::string commit;                    // git HEAD of the source tree ("" if unknown)
  bool dirty = false;                    // uncommitted changes in the source tree
  bool subset = false;                   // scenes, techniques or levels were restricted
  std::string suite;
  int frames = 0, warmup = 0;
  std::string started_utc;               // ISO 8601
  double duration_s = 0.0;
};

// Sets LP_NUM_THREADS=2 when it is unset (lavapipe reads it when a device is created, so call this
// before any Vulkan instance exists) and returns the value now in effect.
std::string ensure_lp_num_threads();
// A technique's levels named by `items` (indices, level names, "last" = the cheapest; empty or
// {"all"} = every level), sorted; BadUsage naming the item and listing the levels.
Expected<std::vector<int>> resolve_levels(const std::string& technique, const std::vector<std::string>& items);

Expected<BenchResult> run_bench(const BenchSettings& settings);

// Suite-wide figures of one technique level: mean over scenes of the sustained ms and ratio,
// error pooled over every measured frame of every scene. Used by the report and the plot.
struct LevelAggregate {
  std::string technique, level_name;
  int level = 0;
  size_t scenes = 0;
  double mean_median_ms = 0.0, mean_median_ratio = 0.0;
  double mean_cpu_ms = 0.0;  // mean over scenes of BenchEntry::cpu_ms
  double max_memory_mib = 0.0;
  bool has_reference = false;
  RdeReport error;
};
std::vector<LevelAggregate> aggregate_levels(const BenchResult& result);

}  // namespace mrgi::perf
