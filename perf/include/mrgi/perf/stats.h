// Order statistics over timing samples, shared by the bench and its reports.
#pragma once
#include <cstddef>
#include <vector>

namespace mrgi::perf {

// p-th percentile (0..100) by nearest rank; 0 for an empty sample. Median = percentile(v, 50).
double percentile(std::vector<double> v, double p);
// The median, the mean of the two middle values for an even count; 0 for an empty sample.
double median(std::vector<double> v);
// Removes the samples that are not above 0 (a GPU timestamp pair that did not resolve: no pass
// takes no time, and one 0 ms median would make every ratio over it infinite); returns how many
// it removed.
size_t drop_unresolved_times(std::vector<double>& v);

}  // namespace mrgi::perf
