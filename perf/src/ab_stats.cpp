#include "mrgi/perf/ab_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "mrgi/perf/stats.h"

namespace mrgi::perf {
namespace {

// Ranks (1-based) of the magnitudes, ties sharing their mean rank, doubled so they are integers.
std::vector<int> doubled_ranks(const std::vector<double>& magnitude) {
  const size_t n = magnitude.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return magnitude[a] < magnitude[b]; });
  std::vector<int> rank2(n);
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j + 1 < n && magnitude[order[j + 1]] == magnitude[order[i]]) ++j;
    // Ranks i+1 .. j+1 share their mean (i + j + 2) / 2: doubled, i + j + 2.
    for (size_t k = i; k <= j; ++k) rank2[order[k]] = int(i + j + 2);
    i = j + 1;
  }
  return rank2;
}

double normal_upper_tail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

}  // namespace

double signed_rank_p_greater(const std::vector<double>& d) {
  std::vector<double> kept, magnitude;
  for (double x : d)
    if (std::isfinite(x) && x != 0.0) {
      kept.push_back(x);
      magnitude.push_back(std::abs(x));
    }
  const size_t n = kept.size();
  if (n == 0) return 1.0;
  const std::vector<int> rank2 = doubled_ranks(magnitude);
  int w2 = 0, total2 = 0;
  for (size_t i = 0; i < n; ++i) {
    total2 += rank2[i];
    if (kept[i] > 0.0) w2 += rank2[i];
  }
  if (n <= kExactPairs) {
    // The distribution of the doubled positive-rank sum under random signs, each rank in or out
    // with probability 1/2.
    std::vector<double> prob(size_t(total2) + 1, 0.0), next(prob.size());
    prob[0] = 1.0;
    int reach = 0;
    for (size_t i = 0; i < n; ++i) {
      const int r = rank2[i];
      std::fill(next.begin(), next.begin() + reach + r + 1, 0.0);
      for (int s = 0; s <= reach; ++s) {
        next[size_t(s)] += 0.5 * prob[size_t(s)];
        next[size_t(s + r)] += 0.5 * prob[size_t(s)];
      }
      reach += r;
      std::swap(prob, next);
    }
    double p = 0.0;
    for (int s = w2; s <= total2; ++s) p += prob[size_t(s)];
    return std::clamp(p, 0.0, 1.0);
  }
  // Normal approximation with continuity correction; the variance of a sum of +-r_i/2 terms.
  double var = 0.0;
  for (int r : rank2) var += 0.25 * (0.5 * r) * (0.5 * r);
  const double w = 0.5 * w2, mean = 0.25 * total2;
  return normal_upper_tail((w - mean - 0.5) / std::sqrt(var));
}

std::vector<double> holm_adjust(const std::vector<double>& p) {
  const size_t m = p.size();
  std::vector<size_t> order(m);
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p[a] < p[b]; });
  std::vector<double> adjusted(m, 1.0);
  double running = 0.0;
  for (size_t k = 0; k < m; ++k) {
    const double v = std::isfinite(p[order[k]]) ? std::min(1.0, double(m - k) * p[order[k]]) : 1.0;
    running = std::max(running, v);
    adjusted[order[k]] = running;
  }
  return adjusted;
}

size_t min_pairs_for(size_t quantities, double alpha) {
  if (quantities == 0 || !(alpha > 0.0)) return 0;
  return size_t(std::ceil(std::log2(double(quantities) / alpha) - 1e-9));
}

AbJudgement judge_pairs(std::string name, const std::vector<double>& base, const std::vector<double>& candidate,
                        const AbRule& rule) {
  AbJudgement j;
  j.name = std::move(name);
  std::vector<double> d;
  for (size_t i = 0; i < std::min(base.size(), candidate.size()); ++i) {
    const double b = base[i], c = candidate[i];
    if (std::isfinite(b) && std::isfinite(c) && b > 0.0 && c > 0.0) d.push_back(std::log(c / b));
  }
  j.pairs = d.size();
  if (d.empty()) return j;
  j.median_ratio = std::exp(median(d));
  std::mt19937_64 rng(rule.seed);
  std::uniform_int_distribution<size_t> pick(0, d.size() - 1);
  std::vector<double> medians, resample(d.size());
  medians.reserve(size_t(std::max(rule.bootstrap, 1)));
  for (int b = 0; b < rule.bootstrap; ++b) {
    for (double& x : resample) x = d[pick(rng)];
    medians.push_back(median(resample));
  }
  j.ratio_low = std::exp(percentile(medians, 2.5));
  j.ratio_high = std::exp(percentile(medians, 97.5));
  const double shift = std::log1p(std::max(rule.min_slowdown, 0.0));
  std::vector<double> shifted(d);
  for (double& x : shifted) x -= shift;
  j.p_value = signed_rank_p_greater(shifted);
  j.p_adjusted = j.p_value;
  return j;
}

void judge_family(std::vector<AbJudgement>& family, const AbRule& rule) {
  std::vector<double> p;
  p.reserve(family.size());
  for (const AbJudgement& j : family) p.push_back(j.p_value);
  const std::vector<double> adjusted = holm_adjust(p);
  for (size_t i = 0; i < family.size(); ++i) {
    family[i].p_adjusted = adjusted[i];
    family[i].alarm = family[i].pairs > 0 && adjusted[i] <= rule.alpha;
  }
}

}  // namespace mrgi::perf
