// A/B comparison of two builds of mrgi (`mrgi bench --compare BASE`): the base and the
// candidate each run as a worker process (`mrgi bench --serve`, which keeps the inputs loaded),
// measured one after the other
// on the same entry and the same preloaded inputs, ABAB... (the order alternating pair to pair
// so a machine speeding up or slowing down over the run moves both alike), never both at once;
// each quantity (an entry's sustained ms and process CPU ms per frame, each main pass's
// fastest profiled frame over the rest of the measurement's passes) is judged by
// mrgi/perf/ab_stats.h's rule over all quantities together.
//
// The worker protocol (one JSON object per line; the worker answers each request with one
// line): on start the worker writes {"ok":true,"protocol":1,"device":...,"commit":...}; a
// request {"op":"measure","suite":PATH,"scene":NAME,"technique":T,"level":NAME_OR_INDEX_OR_auto,
// "frames":F,"warmup":W,"profile_frames":P,"fresh":true} runs W + F frames back to back (2 in
// flight) and P frames in profiling mode on a runtime made for the request (its creation not
// timed; with "fresh":false the entry's runtime is kept while the requests stay on it) and
// answers {"ok":true,"level_name":...,
// "sustained_ms":...,"cpu_ms":...,"profiled_ms":...,"passes":{"NAME":median ms,...},
// "passes_min":{"NAME":fastest frame's ms,...}} (level "auto": also "budget_frames" and
// "within_budget_frames", the sustained frames and those whose cost was within the budget, and
// "mean_level", the scheduler's mean level index over them) or
// {"ok":false,"error":...}; {"op":"quit"} ends it.
#pragma once
#include <functional>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/perf/ab_stats.h"

namespace mrgi::perf {

// One entry of a comparison: a suite scene at one technique's level (a name, an index or
// "last"), or "auto": the frame-budget scheduler choosing the level (kAutoLevel, the default
// budget), judged by its share of frames within the budget (kSchedulerMetric), not by time.
struct AbEntry {
  std::string scene, technique, level;
};

// The entry sets of a comparison manifest (perf/compare.json): {"version":1,"sets":{NAME:
// [{"scene":...,"technique":...,"level":...},...],...}}. BadInput naming the file, the field and
// the rule.
Expected<std::vector<AbEntry>> load_compare_set(const std::string& path, const std::string& set);

// A pass's time over the rest of one measurement's passes (`passes`: name -> ms, each pass by
// its fastest profiled frame): what the comparison judges a pass by. The machine speeding up
// or slowing down between measurements moves the pass and the rest alike and drops out; NaN
// where the pass is missing or the rest is 0.
double pass_over_rest(const std::map<std::string, double>& passes, const std::string& pass);

struct AbSettings {
  std::string suite;                 // suite manifests, comma-separated, holding the entries' scenes
  std::vector<AbEntry> entries;
  std::string base_binary, candidate_binary;  // mrgi executables with `bench --serve`
  int pairs = 14;                    // measurements of each build per entry (see min_pairs_for)
  int frames = 8, warmup = 2;        // per measurement: sustained frames after warm-up frames
  int profile_frames = 6;            // per measurement: profiling-mode frames (0 = no pass judged)
  // Per measurement of an "auto" entry: frames whose cost is compared with the budget, after
  // warm-up frames in which the scheduler settles from its priors (no profiling-mode frames:
  // they would time the passes apart and mislead it).
  int scheduler_frames = 40, scheduler_warmup = 10;
  // Passes judged: those taking at least this share of the base's profiled frame (below it a
  // pass's time is mostly noise and the family grows for nothing).
  double pass_min_share = 0.10;
  std::string device;                // Vulkan device selector for both workers
  AbRule rule;
  std::function<void(const std::string&, size_t, size_t, double)> progress;  // optional
};

// The quantity an "auto" entry is judged by: frames run per frame within the budget, (n + 2) /
// (k + 1) for k of n frames within it (1.05: 95 % within; Laplace's +1 keeps a run with none
// within finite). Larger is worse, as a time is, so the same rule judges it: a candidate whose
// scheduler holds the budget in fewer frames alarms.
inline constexpr const char* kSchedulerMetric = "frames_per_frame_within_budget";

// One judged quantity with its samples (base[i] and candidate[i] measured one after the other).
struct AbQuantity {
  std::string scene, technique, level_name, metric;  // metric: sustained_ms, cpu_ms, pass:NAME
  std::vector<double> base, candidate;
  AbJudgement judgement;
  // "scene/technique/level", or "every entry (N entries)" for a pass pooled over entries.
  std::string entry() const {
    return technique.empty() ? scene + " (" + level_name + ")" : scene + "/" + technique + "/" + level_name;
  }
};

// For each pass judged in at least two entries, one more quantity: its pairs from every such
// entry together ("every entry", level_name "N entries"). A pass slowed wherever it runs (the
// direct-light block's, a reconstruction step's) shows in N x pairs pairs, where each entry's
// own pairs leave a 10 % change short of the family's bar; a change to one entry's use of it is
// still judged on that entry. Judged by `rule` alone (the family's adjustment comes after).
std::vector<AbQuantity> pool_pass_quantities(const std::vector<AbQuantity>& quantities, const AbRule& rule);

struct AbResult {
  std::vector<AbQuantity> quantities;
  std::string base_binary, candidate_binary, base_commit, candidate_commit, device, lp_num_threads;
  int pairs = 0, frames = 0, warmup = 0, profile_frames = 0;
  AbRule rule;
  double duration_s = 0.0;
  size_t alarms() const;
};

Expected<AbResult> run_ab_compare(const AbSettings& settings);

// compare.md (the paired figures per quantity and the verdict), compare.json, junit.xml (a test
// case per quantity, failed where it alarms) and ratios.png (each quantity's median ratio with
// its interval) into `dir`.
Status write_ab_outputs(const std::string& dir, const AbResult& result);

// The worker's loop over `in` (requests) and `out` (answers); returns the process exit status.
int serve_bench_worker(std::istream& in, std::ostream& out, const std::string& device);

}  // namespace mrgi::perf
