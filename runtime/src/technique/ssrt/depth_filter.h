// The image-space depth filter chain of the ssrt technique (paper Sec. 4, eq. 1-5): D' merges
// the raw depth D_c with the depth ray-cast from the fused volume D_v, D'' is a joint bilateral
// median (colour edges), D''' a small plain median. This is the CPU reference: the compute
// shaders in shaders/ssrt/depth_*.comp implement the same rules and the tests compare them.
//
// Reading of the paper's window sizes: "k" is the side of the k x k support window; even k is
// rounded up to the next odd side so the window is centred on p (k = 20 -> 21 x 21, k = 8 ->
// 9 x 9, k = 2 -> 3 x 3). For the medians of D' and D'' the window is sub-sampled to 5 x 5 taps
// (stride (side - 1) / 4), as the paper does for cost; D''' uses every pixel of its window.
// Medians of an even count take the lower middle element, so the result is always one of the
// inputs (never an average across a depth edge).
#pragma once
#include <cstdint>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi::ssrt {

struct DepthFilterSettings {
  uint32_t merge_window = 20;        // k of D' (eq. 1-3), pixels (paper: 20)
  uint32_t bilateral_window = 8;     // k of D'' (eq. 4), pixels (paper: 8)
  uint32_t final_window = 2;         // k of D''' (eq. 5), pixels (paper: 2)
  float intensity_threshold = 7.0f;  // lambda_I, in 8-bit grey levels 0..255 (paper: 7)
  float depth_threshold_m = 0.05f;   // lambda_D, metres (paper: 5 cm)
  uint32_t median_taps = 5;          // sub-sampled taps per side for D' and D'' (paper: 5)
  bool final_pass = true;            // D''' (the paper's mobile variant drops it)
};

// Images are row-major width x height. Depth in metres, 0 = no measurement (D_c) or no surface
// (D_v); intensity is grey 0..255.
struct DepthFilterInput {
  uint32_t width = 0, height = 0;
  const float* depth_camera = nullptr;   // D_c
  const float* depth_volume = nullptr;   // D_v (may be null: no volume yet, all missing)
  const float* intensity = nullptr;      // I_c
};

struct DepthFilterOutput {
  std::vector<float> merged;    // D'
  std::vector<float> bilateral; // D''
  std::vector<float> final;     // D''' (== D'' when final_pass is off)
};

// BadUsage for settings out of range, BadInput for missing or mismatched images.
Status validate(const DepthFilterSettings& settings);
Expected<DepthFilterOutput> filter_depth_reference(const DepthFilterInput& input,
                                                   const DepthFilterSettings& settings);

// The window side actually used for a paper k (odd, >= 1) and the tap stride for `taps` taps.
uint32_t window_side(uint32_t k);
uint32_t window_stride(uint32_t side, uint32_t taps);

}  // namespace mrgi::ssrt
