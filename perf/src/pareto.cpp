#include "mrgi/perf/pareto.h"

#include <algorithm>
#include <cmath>

namespace mrgi::perf {

std::vector<size_t> pareto_front(const std::vector<ParetoPoint>& points) {
  auto finite = [](const ParetoPoint& p) { return std::isfinite(p.cost) && std::isfinite(p.error); };
  std::vector<size_t> front;
  // O(n^2) is fine: a suite has tens of technique levels.
  for (size_t i = 0; i < points.size(); ++i) {
    if (!finite(points[i])) continue;
    bool dominated = false;
    for (size_t j = 0; j < points.size() && !dominated; ++j) {
      if (j == i || !finite(points[j])) continue;
      const ParetoPoint &a = points[j], &b = points[i];
      dominated = a.cost <= b.cost && a.error <= b.error && (a.cost < b.cost || a.error < b.error);
    }
    if (!dominated) front.push_back(i);
  }
  std::sort(front.begin(), front.end(), [&](size_t a, size_t b) {
    if (points[a].cost != points[b].cost) return points[a].cost < points[b].cost;
    if (points[a].error != points[b].error) return points[a].error < points[b].error;
    return a < b;
  });
  return front;
}

}  // namespace mrgi::perf
