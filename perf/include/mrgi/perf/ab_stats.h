// The statistical rule of the A/B performance comparison (`mrgi bench --compare`): is the
// candidate build slower than the base build on one measured quantity (an entry's sustained ms,
// its process CPU ms per frame, one pass's profiled ms), and over all the quantities of a
// comparison, which ones are slower beyond chance?
//
// Per quantity the samples are paired: sample i of the base and of the candidate come from
// two runs made one right after the other on the same inputs (ABAB...), so a machine that
// speeds up or slows down over the comparison moves both alike. On the log ratios
// d_i = ln(candidate_i / base_i):
//   - the effect is exp(median d) (the median paired ratio), with a bootstrap 95 % interval of
//     it for the report;
//   - the test is Wilcoxon's signed-rank test, one-sided, of d_i - ln(1 + min_slowdown) > 0
//     ("the candidate is slower by more than min_slowdown"), exact for up to kExactPairs pairs:
//     it assumes only that the shifted log ratios are symmetric about their median under the
//     null, not that they are normal (a burst of load is an outlier, not a shift);
//   - over the family of quantities judged together, Holm's step-down adjustment holds the
//     chance of any false alarm at alpha (family-wise), however many entries and passes are
//     judged.
// A quantity alarms when its Holm-adjusted p-value is below alpha. Because the test's smallest
// p-value with n pairs is 2^-n, a family of m quantities needs n >= log2(m / alpha) pairs for
// any alarm to be possible: `min_pairs_for` says how many (10 pairs for up to 51 quantities at
// alpha 0.05).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mrgi::perf {

struct AbRule {
  double min_slowdown = 0.02;  // a slowdown smaller than this (2 %) is never an alarm, >= 0
  double alpha = 0.05;         // family-wise false-alarm rate (Holm), 0..1
  int bootstrap = 2000;        // resamples for the reported interval, >= 100
  uint64_t seed = 1;           // of the bootstrap (deterministic reports)
};

struct AbJudgement {
  std::string name;            // what was measured: "scene/technique/level metric"
  size_t pairs = 0;
  double median_ratio = 1.0;   // candidate / base
  double ratio_low = 1.0, ratio_high = 1.0;  // bootstrap 95 % interval of the median ratio
  double p_value = 1.0;        // one-sided, before the family's adjustment
  double p_adjusted = 1.0;     // Holm
  bool alarm = false;
};

// Up to this many pairs the signed-rank test's p-value is exact; above, the normal
// approximation with the tie correction.
inline constexpr size_t kExactPairs = 64;

// One-sided p-value of Wilcoxon's signed-rank test that the differences `d` are centred above
// 0: P(W+ >= observed) under random signs. Zeros are dropped (Wilcoxon's convention); tied
// magnitudes share their mean rank. 1 when nothing is left.
double signed_rank_p_greater(const std::vector<double>& d);

// Holm's step-down adjusted p-values, in the input's order (monotone, at most 1).
std::vector<double> holm_adjust(const std::vector<double>& p);

// The pairs needed so that one quantity of a family of `quantities` can alarm at all.
size_t min_pairs_for(size_t quantities, double alpha);

// Judges one quantity's paired samples (the same count; non-positive or non-finite samples
// make the pair left out). p_adjusted and alarm are set by judge_family.
AbJudgement judge_pairs(std::string name, const std::vector<double>& base, const std::vector<double>& candidate,
                        const AbRule& rule);

// Sets p_adjusted (Holm over the family) and alarm of every judgement.
void judge_family(std::vector<AbJudgement>& family, const AbRule& rule);

}  // namespace mrgi::perf
