// Order statistics over timing samples, shared by the bench and its reports.
#pragma once
#include <vector>

namespace mrgi::perf {

// p-th percentile (0..100) by nearest rank; 0 for an empty sample. Median = percentile(v, 50).
double percentile(std::vector<double> v, double p);
// The median, the mean of the two middle values for an even count; 0 for an empty sample.
double median(std::vector<double> v);

}  // namespace mrgi::perf
