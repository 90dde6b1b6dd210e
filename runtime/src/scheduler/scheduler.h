// The frame-budget scheduler (docs/DESIGN.md "Scheduler and skipping"): after each completed frame it
// reads what the frame cost and chooses the next frame's quality level and, inside the level, its
// internal resolution, so that frames fit the budget with a margin and quality does not flicker.
// Pure host logic on numbers: it never allocates after construction, never waits on the device
// and is unit-tested on simulated cost traces (tests/unit/test_scheduler.cpp).
//
// How it decides (constants in mrgi/runtime.h SchedulerSettings, with where each comes from):
//   - the signal is a high quantile (`quantile`, 0.95) of the cost of the last `window_frames`
//     frames at the current level, spikes over twice the median left out (an order statistic,
//     as Filament's median, so a spike moves nothing; higher than the median because a CPU
//     device's frame times scatter), each
//     frame's cost normalised to full internal resolution with the cost model below; the
//     model learns each level's cost from the window's median;
//   - the target is the budget less `headroom` (Unreal's 10 %); inside a dead band around it
//     (Filament's -1 % / +5 %) nothing changes;
//   - internal resolution is the continuous knob inside a level: a damped step of the scale
//     toward the one the model says meets the target (Filament: a PI controller on the scale;
//     here the model's answer is the proportional part and the damping keeps a noisy median
//     from stepping it far), between `min_scale` and 1;
//   - a step in the load (`step_frames` frames in a row over the budget) drops the scale to
//     `min_scale` at once, without waiting for the window; it climbs back at `scale_gain_up`;
//   - a level changes only when the scale cannot absorb the error: down when even `min_scale`
//     misses the target (by the window's 0.75 quantile), up when the better level is predicted to fit at a scale of at least
//     `upgrade_min_scale`; never more often than `min_frames_between_changes` (Unreal's minimum
//     frames between changes), except that `emergency_frames` consecutive frames over
//     `emergency_factor` x the budget drop a level at once (Unreal's limit on consecutive
//     over-budget frames);
//   - an upgrade that had to be undone soon after doubles the wait before that level is tried
//     again (up to 16 x), so a level just beyond the budget is not tried every second.
// Cost model: cost(level, scale) = c_level x (fixed + (1 - fixed) x scale^2): a part of a frame
// does not scale with pixels (maps, volumes, VPLs, host work) and the rest does. c_level is an
// exponential average of the normalised costs seen at that level; a level not seen yet is
// predicted from the nearest seen one by the ratio of their prior costs (a bench table, or the
// built-in one), and learns its own once it runs.
#pragma once
#include <array>
#include <string>
#include <cstdint>
#include <vector>

#include "mrgi/runtime.h"

namespace mrgi::sched {

class Scheduler {
 public:
  // `prior_ms`: a cost per level at full internal resolution (best level first), from a bench
  // table of this device or a built-in one; only their ratios matter until levels are seen.
  Scheduler(const SchedulerSettings& settings, double budget_ms, std::vector<double> prior_ms, int start_level);

  struct Choice {
    int level = 0;
    float scale = 1.0f;        // multiplies the level's internal scale
    double predicted_ms = 0.0; // the model's cost of this choice when it was made
  };
  const Choice& choice() const { return choice_; }

  // A completed frame: the level and scale it ran at, its cost (ms), and whether the technique
  // ran (a frame with nothing virtual in view costs the skeleton, not the level: it is not
  // taken into the model). Updates choice().
  void observe(int level, float scale, double cost_ms, bool technique_ran);

  // The model's cost of `level` at `scale` (ms).
  double predict(int level, float scale) const;
  double budget_ms() const { return budget_ms_; }
  void set_budget_ms(double budget_ms) { budget_ms_ = budget_ms; }
  int level_changes() const { return level_changes_; }

  // The part of a frame's cost that does not scale with the number of pixels.
  static constexpr double kFixedFraction = 0.3;
  static double scale_factor(float scale) { return kFixedFraction + (1.0 - kFixedFraction) * double(scale) * double(scale); }
  // The scale whose factor is `factor` (clamped to [0, 1]).
  static float scale_for_factor(double factor);

 private:
  static constexpr int kMaxWindow = 64;
  static constexpr double kSpikeFactor = 2.0;  // normalised_quantile: a spike is over this x the median
  static constexpr int kWarmupFrames = 1;  // the runtime primes its first frame (runtime.cpp)
  void change_level(int level);
  double normalised_quantile(double q) const;  // of the window (normalised to full scale)
  SchedulerSettings s_;
  double budget_ms_;
  std::vector<double> prior_;     // per level, ms at scale 1
  std::vector<double> model_;     // per level, learned ms at scale 1 (0 = not seen)
  std::vector<int> cooldown_;     // per level, frames to wait before an upgrade to it
  std::vector<int64_t> left_at_;  // per level, frame count when it was last left downward
  std::array<double, kMaxWindow> window_{};  // normalised costs at the current level
  int window_count_ = 0, window_next_ = 0;
  int over_ = 0;                  // consecutive frames over the emergency line
  int over_budget_ = 0;           // consecutive frames over the budget
  int64_t frames_ = 0, changed_at_ = -1000000;
  int upgraded_to_ = -1;          // the last upgrade's level and when it was taken
  int64_t upgraded_at_ = -1000000;
  int level_changes_ = 0;
  Choice choice_;
};

// The frame budget and RuntimeSettings::scheduler's constants (and level_costs_ms against a
// ladder of `levels`), each refused as BadUsage naming its field and rule.
Status check_settings(const RuntimeSettings& settings, size_t levels);

// Relative cost priors of a technique's ladder (ms at 640x480 on lavapipe x2 from the bench,
// perf/results/scheduler/README.md), best level first; equal steps where none is known.
std::vector<double> builtin_level_costs(const std::string& technique, int levels);

}  // namespace mrgi::sched
