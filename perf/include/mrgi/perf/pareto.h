// The Pareto front of (cost, error) points: a point is on the front when no other point is at
// least as good in both and strictly better in one. Lower is better on both axes.
#pragma once
#include <cstddef>
#include <vector>

namespace mrgi::perf {

struct ParetoPoint {
  double cost = 0.0;   // e.g. median frame ms
  double error = 0.0;  // e.g. RDE
};

// Indices of the points on the front, sorted by cost (ties by error). Points with a non-finite
// coordinate are never on the front and never dominate. Identical points are all kept.
std::vector<size_t> pareto_front(const std::vector<ParetoPoint>& points);

}  // namespace mrgi::perf
