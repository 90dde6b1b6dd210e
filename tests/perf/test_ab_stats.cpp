// The A/B comparison's statistical rule (mrgi/perf/ab_stats.h): the signed-rank test against
// hand-counted distributions, Holm's adjustment against a worked example, and the rule as a
// whole on simulated comparisons: no false alarm where base and candidate are the same build,
// a 10 % slowdown of one quantity found among many.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mrgi/perf/ab_stats.h"

using namespace mrgi::perf;

// n = 3, ranks 1..3: the 8 sign patterns give W+ = 0, 1, 2, 3, 3, 4, 5, 6.
TEST(AbStats, SignedRankTestIsExactForFewPairs) {
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({1.0, 2.0, 3.0}), 1.0 / 8.0);
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({1.0, -2.0, 3.0}), 3.0 / 8.0);
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({-1.0, -2.0, -3.0}), 1.0);
  // Tied magnitudes share rank 2: W+ in {0, 2, 2, 2, 4, 4, 4, 6}, observed 4.
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({0.5, 0.5, -0.5}), 4.0 / 8.0);
  // Zeros are dropped; nothing left is no evidence.
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({0.0, 1.0, 2.0, 3.0}), 1.0 / 8.0);
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({}), 1.0);
  EXPECT_DOUBLE_EQ(signed_rank_p_greater({0.0, NAN}), 1.0);
}

// Above kExactPairs the normal approximation takes over where the exact count leaves off.
TEST(AbStats, SignedRankApproximationMeetsTheExactCount) {
  std::vector<double> d;
  for (size_t i = 0; i < kExactPairs; ++i) d.push_back((i % 3 == 0 ? -1.0 : 1.0) * double(i + 1));
  const double exact = signed_rank_p_greater(d);
  d.push_back(-0.5);  // the smallest rank, negative: one more pair, nearly the same evidence
  const double approx = signed_rank_p_greater(d);
  EXPECT_GT(exact, 0.0);
  EXPECT_LT(exact, 0.2);
  EXPECT_NEAR(approx, exact, 0.01);
}

TEST(AbStats, HolmAdjustsStepDown) {
  // Sorted 0.005, 0.01, 0.03, 0.04 times 4, 3, 2, 1: 0.02, 0.03, 0.06, 0.04 -> monotone 0.06.
  const std::vector<double> adjusted = holm_adjust({0.01, 0.04, 0.03, 0.005});
  ASSERT_EQ(adjusted.size(), size_t(4));
  EXPECT_NEAR(adjusted[0], 0.03, 1e-12);
  EXPECT_NEAR(adjusted[1], 0.06, 1e-12);
  EXPECT_NEAR(adjusted[2], 0.06, 1e-12);
  EXPECT_NEAR(adjusted[3], 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(holm_adjust({0.5, 0.9})[1], 1.0);
  EXPECT_TRUE(holm_adjust({}).empty());
}

TEST(AbStats, PairsNeededForAnAlarmToBePossible) {
  EXPECT_EQ(min_pairs_for(1, 0.05), size_t(5));    // 2^-5 = 0.031 <= 0.05
  EXPECT_EQ(min_pairs_for(51, 0.05), size_t(10));  // 2^-10 x 51 = 0.0498
  EXPECT_EQ(min_pairs_for(52, 0.05), size_t(11));
  // And with that many pairs all slower, the family's adjusted p-value reaches alpha.
  std::vector<double> d(10, 0.2);
  EXPECT_LE(signed_rank_p_greater(d) * 51.0, 0.05);
}

TEST(AbStats, JudgesTheMedianPairedRatio) {
  AbRule rule;
  const std::vector<double> base = {10, 11, 10.5, 9.8, 10.2, 10.1, 10.4, 9.9, 10.3, 10.6};
  std::vector<double> slower = base, same = base;
  for (double& x : slower) x *= 1.25;
  const AbJudgement s = judge_pairs("slower", base, slower, rule);
  EXPECT_EQ(s.pairs, size_t(10));
  EXPECT_NEAR(s.median_ratio, 1.25, 1e-9);
  EXPECT_NEAR(s.ratio_low, 1.25, 1e-9);
  EXPECT_NEAR(s.ratio_high, 1.25, 1e-9);
  EXPECT_NEAR(s.p_value, std::pow(0.5, 10), 1e-12);
  const AbJudgement z = judge_pairs("same", base, same, rule);
  EXPECT_NEAR(z.median_ratio, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(z.p_value, 1.0);  // every log ratio is 0 - ln(1.02) < 0
  // A slowdown below min_slowdown is not evidence, however consistent.
  std::vector<double> slight = base;
  for (double& x : slight) x *= 1.015;
  EXPECT_DOUBLE_EQ(judge_pairs("slight", base, slight, rule).p_value, 1.0);
  // Pairs with a non-positive or non-finite sample are left out.
  const AbJudgement holes = judge_pairs("holes", {1.0, 0.0, NAN, 2.0}, {1.5, 1.0, 1.0, 3.0}, rule);
  EXPECT_EQ(holes.pairs, size_t(2));
  std::vector<AbJudgement> family = {s, z};
  judge_family(family, rule);
  EXPECT_TRUE(family[0].alarm);
  EXPECT_FALSE(family[1].alarm);
  EXPECT_NEAR(family[0].p_adjusted, 2.0 * std::pow(0.5, 10), 1e-12);
}

// Simulated comparisons: 40 quantities, 16 pairs each, every sample with independent
// log-normal noise of 3 % and, per pair, a machine-wide factor of up to +-15 % shared by its two
// runs (what interleaving cancels). With base = candidate no family alarms (the rule's
// family-wise rate is at most 5 %; the 2 % margin makes it far smaller: none in 200 such
// families simulated apart); one quantity 10 % slower is found in at least 90 % of the families
// (96-99 % simulated apart), and nothing else alarms.
TEST(AbStats, NoFalseAlarmsAndPlantedSlowdownsFound) {
  AbRule rule;
  rule.bootstrap = 100;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::uniform_real_distribution<double> machine(-0.15, 0.15);
  auto family_of = [&](double slowdown) {
    std::vector<AbJudgement> family;
    for (int q = 0; q < 40; ++q) {
      std::vector<double> a, b;
      for (int i = 0; i < 16; ++i) {
        const double level = 5.0 * (1.0 + q % 7) * std::exp(machine(rng));
        a.push_back(level * std::exp(noise(rng)));
        b.push_back(level * std::exp(noise(rng)) * (q == 0 ? 1.0 + slowdown : 1.0));
      }
      family.push_back(judge_pairs("q" + std::to_string(q), a, b, rule));
    }
    judge_family(family, rule);
    return family;
  };
  int false_families = 0, found = 0, wrong = 0;
  const int families = 100;
  for (int f = 0; f < families; ++f) {
    for (const AbJudgement& j : family_of(0.0)) false_families += j.alarm ? 1 : 0;
    const std::vector<AbJudgement> planted = family_of(0.10);
    found += planted[0].alarm ? 1 : 0;
    for (size_t q = 1; q < planted.size(); ++q) wrong += planted[q].alarm ? 1 : 0;
  }
  EXPECT_EQ(false_families, 0);
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(found, 90) << "of " << families;
}
