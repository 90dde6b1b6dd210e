// Camera matrices for the runtime: the colour camera's OpenCV intrinsics as a Vulkan projection.
#pragma once
#include <glm/glm.hpp>

#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi::runtime_detail {

inline constexpr float kCameraNear = 0.05f;  // metres
inline constexpr float kCameraFar = 100.0f;  // metres

// OpenCV camera space (x right, y down, +z forward) -> Vulkan clip space for an image of
// k.width x k.height: x_ndc = 2 (u + 0.5) / W - 1 with u = fx x / z + cx (pixel centres at
// integers, as OpenCV), y likewise (Vulkan's y is down too), depth 0 at kCameraNear and 1 at
// kCameraFar.
glm::mat4 opencv_projection(const Intrinsics& k, float near_m = kCameraNear, float far_m = kCameraFar);

}  // namespace mrgi::runtime_detail
