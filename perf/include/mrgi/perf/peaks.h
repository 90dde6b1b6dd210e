// This machine's peaks as a Vulkan compute device sees them (`mrgi peaks`): the numbers a
// pass's time is judged against ("floor-pass arithmetic": a pass that needs F FLOPs, B bytes
// streamed and L scattered texel loads cannot take less than max(F / fma, B / copy, L / loads)).
// Every kernel is timed as the bench times a pass (profiling mode: submitted alone, host clock
// from submit to fence, less an empty submission), median of `repeats`, beside the floor pass
// measured in the same process.
//   fma         8 independent vec4 multiply-add chains per invocation (shaders/perf/peak_fma.comp)
//   copy        a 16-byte-per-invocation buffer copy, 2 x 64 MiB touched (peak_copy.comp)
//   image load  RGBA32F imageLoad at hashed positions within 64 px (peak_image_load.comp), the
//               access pattern of a screen-space sampling pass
//   buffer gather the same access pattern from a storage buffer (peak_buffer_gather.comp): what a
//               scattered read pays for the image path
//   buffer floor the floor pass's per-pixel load and store (4 bytes each) through storage
//               buffers instead of images (peak_buffer_floor.comp): what the image path costs
#pragma once
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {

struct PeaksSettings {
  DeviceSettings device;
  int repeats = 7;                 // timed runs per kernel (>= 1); the median is reported
  int fma_invocations = 307200;    // one per pixel of 640 x 480
  int fma_iterations = 256;        // rounds of 32 FMAs per invocation
  int copy_mib = 64;               // size of each of the two buffers
  int image_loads = 16;            // loads per invocation (one invocation per pixel of 640 x 480)
};

struct PeakResult {
  std::string name;
  double median_ms = 0.0, min_ms = 0.0;
  double work = 0.0;               // FLOPs, bytes or loads of one run
  std::string unit;                // of `rate`: "GFLOP/s", "GB/s", "Gload/s"
  double rate = 0.0;               // work / median time, in `unit`
  double best_rate = 0.0;          // work / min time
};

struct Peaks {
  std::string device, driver;
  int lp_num_threads = 0;          // LP_NUM_THREADS when set (lavapipe's thread count), else 0
  double floor_median_ms = 0.0;    // the floor pass at 640 x 480, same process
  std::vector<PeakResult> results; // fma, copy, image_load, buffer_gather, buffer_floor
};

Expected<Peaks> measure_peaks(const PeaksSettings& settings);
// Markdown table of `p`, with the floor pass expressed in each unit.
std::string peaks_markdown(const Peaks& p);

}  // namespace mrgi::perf
