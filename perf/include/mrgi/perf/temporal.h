// Temporal stability of a composite: how much the output's change to the camera frame (its
// delta, output - camera) moves from one frame to the next on real surfaces that did not move,
// beside the same measure of the ground truth's delta (what a perfect method's frame-to-frame
// change is: the virtual object's effect on a moving view changes, and the truth's noise).
//
// Every real pixel of the current frame with a measured depth is lifted to the world with its
// depth and the frame's pose and projected into the previous frame; where it lands on a pixel
// whose own depth agrees within 2 % (the same surface, not occluded) and that is real in both
// frames, the two deltas are compared there. The figure is the mean absolute difference per
// pixel and channel, linear RGB, over those pixels.
#pragma once
#include <cstddef>

#include <glm/glm.hpp>

#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi::perf {

struct StabilityFrame {
  const ImageRGB8* camera = nullptr;     // sRGB
  const ImageRGBA8* output = nullptr;    // the composite, the camera's size
  const ImageRGB8* reference = nullptr;  // the ground truth (nullptr: none)
  const ImageU8* virtual_mask = nullptr; // non-zero = virtual (nullptr: every pixel real)
  const ImageU16* depth = nullptr;       // registered to the camera, depth_scale units a metre
  glm::dmat4 camera_to_world{1.0};
};

struct StabilityPair {
  size_t pixels = 0;          // static real pixels compared
  double output_change = 0.0; // mean |delta_t - delta_t-1| per pixel and channel, linear
  double truth_change = 0.0;  // the same for the reference's deltas (0 without references)
  bool has_truth = false;
};

// BadInput naming the image when sizes differ from the intrinsics' or an image is missing.
Expected<StabilityPair> delta_stability(const StabilityFrame& previous, const StabilityFrame& current,
                                        const Intrinsics& intrinsics, double depth_scale);

}  // namespace mrgi::perf
