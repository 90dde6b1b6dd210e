#include "scheduler/scheduler.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mrgi::sched {

// The budget and the scheduler's constants, each checked with its field's name and rule.
Status check_settings(const RuntimeSettings& rs, size_t levels) {
  auto bad = [](const std::string& field, const std::string& rule) {
    return fail(ErrorKind::BadUsage, "RuntimeSettings." + field + ": " + rule);
  };
  if (!std::isfinite(rs.frame_budget_ms) || rs.frame_budget_ms <= 0.0 || rs.frame_budget_ms > 1e6)
    return bad("frame_budget_ms", "must be in (0, 1e6] ms");
  const SchedulerSettings& s = rs.scheduler;
  if (!(s.headroom >= 0.0 && s.headroom < 0.9)) return bad("scheduler.headroom", "must be in [0, 0.9)");
  if (s.window_frames < 1 || s.window_frames > 64) return bad("scheduler.window_frames", "must be 1..64");
  if (!(s.quantile >= 0.0 && s.quantile <= 1.0)) return bad("scheduler.quantile", "must be in [0, 1]");
  if (!(s.dead_band_below >= 0.0 && s.dead_band_below < 1.0) || !(s.dead_band_above >= 0.0 && s.dead_band_above < 1.0))
    return bad("scheduler.dead_band_below/above", "must be in [0, 1)");
  if (!(s.scale_gain > 0.0 && s.scale_gain <= 1.0)) return bad("scheduler.scale_gain", "must be in (0, 1]");
  if (!(s.scale_gain_up > 0.0 && s.scale_gain_up <= 1.0)) return bad("scheduler.scale_gain_up", "must be in (0, 1]");
  if (!(s.min_scale >= 0.25f && s.min_scale <= 1.0f)) return bad("scheduler.min_scale", "must be in [0.25, 1]");
  if (!(s.upgrade_min_scale >= s.min_scale && s.upgrade_min_scale <= 1.0f))
    return bad("scheduler.upgrade_min_scale", "must be in [min_scale, 1]");
  if (s.min_frames_between_changes < 0 || s.min_frames_between_changes > 100000)
    return bad("scheduler.min_frames_between_changes", "must be 0..100000");
  if (s.step_frames < 1 || s.step_frames > 1000) return bad("scheduler.step_frames", "must be 1..1000");
  if (s.emergency_frames < 1 || s.emergency_frames > 1000) return bad("scheduler.emergency_frames", "must be 1..1000");
  if (!(s.emergency_factor >= 1.0 && s.emergency_factor <= 100.0)) return bad("scheduler.emergency_factor", "must be in [1, 100]");
  if (!rs.level_costs_ms.empty()) {
    if (rs.level_costs_ms.size() != levels)
      return bad("level_costs_ms", "has " + std::to_string(rs.level_costs_ms.size()) + " costs for a ladder of " +
                                       std::to_string(levels) + " levels");
    for (double c : rs.level_costs_ms)
      if (!std::isfinite(c) || c <= 0.0) return bad("level_costs_ms", "every cost must be a positive number of ms");
  }
  return ok_status();
}

float Scheduler::scale_for_factor(double factor) {
  const double s2 = (factor - kFixedFraction) / (1.0 - kFixedFraction);
  return float(std::sqrt(std::clamp(s2, 0.0, 1.0)));
}

Scheduler::Scheduler(const SchedulerSettings& settings, double budget_ms, std::vector<double> prior_ms, int start_level)
    : s_(settings), budget_ms_(budget_ms), prior_(std::move(prior_ms)) {
  if (prior_.empty()) prior_ = {1.0};
  for (double& p : prior_) p = std::max(p, 1e-3);
  s_.window_frames = std::clamp(s_.window_frames, 1, kMaxWindow);
  s_.min_scale = std::clamp(s_.min_scale, 0.05f, 1.0f);
  model_.assign(prior_.size(), 0.0);
  cooldown_.assign(prior_.size(), 0);
  left_at_.assign(prior_.size(), -1000000);
  choice_.level = std::clamp(start_level, 0, int(prior_.size()) - 1);
  // A cautious start: nothing has been measured on this device and scene, so the first frames
  // aim at three quarters of the target by the priors; the controller raises the resolution as
  // soon as its window shows room (the 8-frame sample otherwise spent its first frames over).
  const double target = budget_ms_ * (1.0 - s_.headroom);
  choice_.scale = std::clamp(scale_for_factor(0.75 * target / std::max(1e-6, predict(choice_.level, 1.0f))), s_.min_scale, 1.0f);
  choice_.predicted_ms = predict(choice_.level, choice_.scale);
}

double Scheduler::predict(int level, float scale) const {
  const size_t l = size_t(level);
  double c = model_[l];
  if (c <= 0.0) {
    // The nearest level with a learned cost, scaled by the priors' ratio; none: the priors as
    // they are (a bench table is in ms; the built-in one too).
    double best = prior_[l];
    int nearest = -1;
    for (int k = 0; k < int(model_.size()); ++k)
      if (model_[size_t(k)] > 0.0 && (nearest < 0 || std::abs(k - level) < std::abs(nearest - level))) nearest = k;
    if (nearest >= 0) best = model_[size_t(nearest)] * prior_[l] / prior_[size_t(nearest)];
    c = best;
  }
  return c * scale_factor(scale);
}

double Scheduler::normalised_quantile(double q) const {
  std::array<double, kMaxWindow> v{};
  std::copy(window_.begin(), window_.begin() + window_count_, v.begin());
  std::sort(v.begin(), v.begin() + window_count_);
  // Spikes are left out: a frame over kSpikeFactor x the window's median is the device's hiccup
  // (a page fault storm, a preempted thread), which no resolution would have fitted; a step in
  // the load moves the median within half a window and the step rule (observe) before that.
  const double median = v[size_t(window_count_ / 2)];
  int n = window_count_;
  while (n > 1 && v[size_t(n - 1)] > kSpikeFactor * median) --n;
  const int k = std::clamp(int(std::floor(q * double(n - 1) + 0.5)), 0, n - 1);
  return v[size_t(k)];
}

void Scheduler::change_level(int level) {
  const int from = choice_.level;
  if (level > from) {  // down: cheaper
    left_at_[size_t(from)] = frames_;
    // Undone soon after it was taken: the upgrade was a mistake, so wait longer before the next.
    int& wait = cooldown_[size_t(from)];
    if (from == upgraded_to_ && frames_ - upgraded_at_ < 4 * s_.min_frames_between_changes)
      wait = std::min(16 * s_.min_frames_between_changes, std::max(2 * s_.min_frames_between_changes, 2 * wait));
    else
      wait = 0;  // held a while: the load changed, the level was right
  } else {
    upgraded_to_ = level;
    upgraded_at_ = frames_;
  }
  choice_.level = level;
  changed_at_ = frames_;
  window_count_ = 0;
  window_next_ = 0;
  over_ = 0;
  over_budget_ = 0;
  ++level_changes_;
}

void Scheduler::observe(int level, float scale, double cost_ms, bool technique_ran) {
  ++frames_;
  if (!std::isfinite(cost_ms) || cost_ms < 0.0) return;
  if (!technique_ran) return;  // the skeleton's cost says nothing about the level
  if (level < 0 || level >= int(model_.size())) return;
  // A runtime's first frames pay for first use (pipelines, page faults of fresh memory): they
  // say nothing of a level's cost.
  if (frames_ <= kWarmupFrames) return;
  if (level != choice_.level) return;  // in flight from before the last change
  const double norm = cost_ms / scale_factor(scale);
  window_[size_t(window_next_)] = norm;
  window_next_ = (window_next_ + 1) % s_.window_frames;
  window_count_ = std::min(window_count_ + 1, s_.window_frames);
  // Learn the level's cost from the window's median (an exponential average with a time
  // constant of about 8 frames; the first median taken as it is).
  if (window_count_ >= std::min(3, s_.window_frames)) {
    double& m = model_[size_t(level)];
    const double med = normalised_quantile(0.5);
    m = m <= 0.0 ? med : m + 0.12 * (med - m);
    // What was learned of the other levels goes stale (it was measured under another load):
    // each drifts toward the current level's cost scaled by the priors' ratio, with a time
    // constant of about 50 frames, so a level left under a load it could not meet is tried
    // again once the load has gone (load test: level 3 held after the load ended).
    for (size_t o = 0; o < model_.size(); ++o)
      if (o != size_t(level) && model_[o] > 0.0) model_[o] += 0.02 * (m * prior_[o] / prior_[size_t(level)] - model_[o]);
  }

  const double target = budget_ms_ * (1.0 - s_.headroom);
  const int last = int(model_.size()) - 1;
  // Emergency: frames far over the budget drop a level at once.
  over_ = cost_ms > s_.emergency_factor * budget_ms_ ? over_ + 1 : 0;
  if (over_ >= s_.emergency_frames && (choice_.level < last || choice_.scale > s_.min_scale)) {
    if (choice_.level < last) {
      change_level(choice_.level + 1);
      choice_.scale = std::clamp(scale_for_factor(target / std::max(1e-6, predict(choice_.level, 1.0f))), s_.min_scale, 1.0f);
    } else {
      choice_.scale = s_.min_scale;
      window_count_ = 0;
      over_ = 0;
    }
    choice_.predicted_ms = predict(choice_.level, choice_.scale);
    return;
  }
  // A step up in the load: the scale follows at once, without waiting for the window.
  over_budget_ = cost_ms > budget_ms_ ? over_budget_ + 1 : 0;
  if (over_budget_ >= s_.step_frames && choice_.scale > s_.min_scale) {
    choice_.scale = s_.min_scale;
    choice_.predicted_ms = predict(choice_.level, choice_.scale);
    over_budget_ = 0;
    return;
  }
  if (window_count_ < std::min(3, s_.window_frames)) return;

  // The controlled signal: the window's quantile (SchedulerSettings::quantile), at full scale.
  const double median_norm = normalised_quantile(s_.quantile);
  const double current = median_norm * scale_factor(choice_.scale);
  const bool may_change_level = frames_ - changed_at_ >= s_.min_frames_between_changes;
  const bool in_band = current >= target * (1.0 - s_.dead_band_below) && current <= target * (1.0 + s_.dead_band_above);

  // Over the budget even at the smallest scale: a cheaper level.
  // Judged on a lower quantile than the scale's (the window's upper quarter may be spikes no
  // level fixes; a level lost for them is a second of worse quality each time).
  if (current > target * (1.0 + s_.dead_band_above) && normalised_quantile(0.75) * scale_factor(s_.min_scale) > target &&
      choice_.level < last && may_change_level) {
    change_level(choice_.level + 1);
    choice_.scale = std::clamp(scale_for_factor(target / std::max(1e-6, predict(choice_.level, 1.0f))), s_.min_scale, 1.0f);
    choice_.predicted_ms = predict(choice_.level, choice_.scale);
    return;
  }
  // Room at full scale: a better level, where it is predicted to fit at upgrade_min_scale or more.
  if (choice_.level > 0 && may_change_level && choice_.scale >= 0.999f && current < target * (1.0 - s_.dead_band_below)) {
    const int better = choice_.level - 1;
    const bool waited = frames_ - left_at_[size_t(better)] >= cooldown_[size_t(better)];
    const double full = predict(better, 1.0f);
    const float fit = scale_for_factor(target / std::max(1e-6, full));
    if (waited && fit >= s_.upgrade_min_scale) {
      change_level(better);
      choice_.scale = fit;
      choice_.predicted_ms = predict(choice_.level, choice_.scale);
      return;
    }
  }
  // Inside the level: the scale, a damped step toward the one the model says meets the target.
  if (!in_band) {
    const double ratio = target / std::max(1e-6, current);
    const double want = scale_factor(choice_.scale) * std::pow(ratio, ratio < 1.0 ? s_.scale_gain : s_.scale_gain_up);
    choice_.scale = std::clamp(scale_for_factor(want), s_.min_scale, 1.0f);
    // Snap to full resolution within a percent: the upgrade test asks for full scale.
    if (choice_.scale > 0.99f) choice_.scale = 1.0f;
  }
  choice_.predicted_ms = predict(choice_.level, choice_.scale);
}

std::vector<double> builtin_level_costs(const std::string& technique, int levels) {
  // Sustained ms per frame at 640x480 on lavapipe with 2 threads, geometric mean over the
  // suite's desk_spot and corner (perf/results/scheduler/README.md "Priors"); the order is the
  // ladder's. A better level may cost less (dlpv's paper level shadows by antiradiance, without
  // maps): the scheduler predicts by these ratios until it has seen a level run.
  struct Table {
    const char* technique;
    std::vector<double> ms;
  };
  static const Table tables[] = {
      {"baseline", {206.9, 124.5, 76.2, 26.8}},
      {"ssrt", {1215.1, 676.5, 42.7, 31.3}},
      {"dlpv", {468.1, 611.8, 178.3, 41.0, 41.3}},
      {"dir", {909.1, 672.5, 244.2, 38.2, 52.7}},
  };
  for (const Table& t : tables)
    if (technique == t.technique && int(t.ms.size()) == levels) return t.ms;
  // A ladder without measurements (a new technique, knobs that changed its levels): each level
  // half again as costly as the next cheaper one, the cheapest at the budget's scale.
  std::vector<double> out(size_t(std::max(levels, 1)));
  for (int i = levels - 1; i >= 0; --i) out[size_t(i)] = 30.0 * std::pow(1.5, double(levels - 1 - i));
  return out;
}

}  // namespace mrgi::sched
