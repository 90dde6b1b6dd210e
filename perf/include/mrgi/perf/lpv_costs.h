// The light propagation volume's cost tables (`mrgi lpv-costs`), measured as the bench times a
// pass (profiling mode: each pass submitted alone, host clock from submit to fence, less an empty
// submission; median of `repeats`), beside the DLPV paper's Table 3 (propagation: volume size x
// steps) and Table 2 (injection: RSM size, every texel a VPL), with the ratio of the shapes: each
// table divided by its own entry at a shared reference (32^3 x 32 steps; RSM 512^2), so a
// device 100x slower than the paper's GTX 470 still shows whether the cost grows the same way.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {

struct LpvCostSettings {
  DeviceSettings device;
  std::vector<uint32_t> volume_sizes{8, 16, 32, 64};  // cells per side (each divides the largest)
  std::vector<uint32_t> steps{8, 16, 32, 64};          // propagation steps
  std::vector<uint32_t> rsm_sizes{256, 512, 1024, 2048};  // texels per side
  int repeats = 3;                                     // timed runs per entry (median reported)
};

struct LpvCosts {
  std::string device, driver;
  int lp_num_threads = 0;
  double floor_median_ms = 0.0;
  struct Propagation {
    uint32_t size = 0, steps = 0;
    double ms = 0.0;
  };
  std::vector<Propagation> propagation;
  struct Injection {
    uint32_t rsm = 0;
    double rho_ms = 0.0, delta_ms = 0.0, direct_ms = 0.0;  // as Table 2's three columns
  };
  std::vector<Injection> injection;
};

Expected<LpvCosts> measure_lpv_costs(const LpvCostSettings& settings,
                                     const std::function<void(const std::string&, size_t, size_t)>& progress = {});
std::string lpv_costs_markdown(const LpvCosts& costs);

}  // namespace mrgi::perf
