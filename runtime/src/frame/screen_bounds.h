// Where a world-space box lands in the internal image: the pixel bounds of its eight corners
// under this frame's camera (FrameConstants::world_to_camera, internal_k), for passes that only
// need to run where something virtual can be (ssrt's tiles and transfer cells, dlpv's indirect
// light inside its volume).
#pragma once
#include <glm/glm.hpp>

#include "common/frame_constants.glsl"

namespace mrgi::frame {

struct ScreenBounds {
  bool visible = false;  // false: one image side (or the camera plane) has every corner outside
  bool behind = false;   // a corner is behind the camera: the bounds below do not hold it
  glm::vec2 min{0.0f}, max{0.0f};  // pixel coordinates of the corners in front (pixel centres at +0.5 - 0.5)
};

inline ScreenBounds project_box(const shader::FrameConstants& fc, glm::vec3 lo, glm::vec3 hi) {
  ScreenBounds b;
  const glm::vec4 k = fc.internal_k;
  const glm::vec2 size(fc.internal_output_size.x, fc.internal_output_size.y);
  int out_count[5] = {0, 0, 0, 0, 0};  // behind, left, right, top, bottom
  b.min = glm::vec2(1e30f);
  b.max = glm::vec2(-1e30f);
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    const glm::vec3 q = glm::vec3(fc.world_to_camera * glm::vec4(p, 1.0f));
    if (q.z <= 1e-4f) {
      ++out_count[0];
      continue;
    }
    const float u = k.x * q.x / q.z + k.z, v = k.y * q.y / q.z + k.w;
    b.min = glm::min(b.min, glm::vec2(u, v));
    b.max = glm::max(b.max, glm::vec2(u, v));
    out_count[1] += u < -0.5f;
    out_count[2] += u > size.x - 0.5f;
    out_count[3] += v < -0.5f;
    out_count[4] += v > size.y - 0.5f;
  }
  for (int side = 0; side < 5; ++side)
    if (out_count[side] == 8) return b;
  b.visible = true;
  b.behind = out_count[0] > 0;
  return b;
}

// The box's pixels as [x0, y0, x1, y1) inside the internal image, with `margin` pixels around
// (filters, rounding); the whole image when a corner is behind the camera; empty (x1 <= x0)
// when it is not visible.
inline glm::ivec4 box_pixels(const shader::FrameConstants& fc, glm::vec3 lo, glm::vec3 hi, int margin) {
  const ScreenBounds b = project_box(fc, lo, hi);
  const glm::ivec2 size(fc.internal_output_size.x, fc.internal_output_size.y);
  if (!b.visible) return glm::ivec4(0);
  if (b.behind) return glm::ivec4(0, 0, size.x, size.y);
  const glm::ivec2 p0 = glm::clamp(glm::ivec2(glm::floor(b.min)) - margin, glm::ivec2(0), size);
  const glm::ivec2 p1 = glm::clamp(glm::ivec2(glm::ceil(b.max)) + 1 + margin, glm::ivec2(0), size);
  return glm::ivec4(p0, p1);
}

}  // namespace mrgi::frame
