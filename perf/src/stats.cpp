#include "mrgi/perf/stats.h"

#include <algorithm>
#include <cmath>

namespace mrgi::perf {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t rank = size_t(std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * double(v.size())));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

size_t drop_unresolved_times(std::vector<double>& v) {
  const size_t before = v.size();
  v.erase(std::remove_if(v.begin(), v.end(), [](double ms) { return !(ms > 0.0); }), v.end());
  return before - v.size();
}

}  // namespace mrgi::perf
