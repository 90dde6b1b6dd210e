// FrameConstants of the simplest frame the GPU tests drive by hand: one pinhole camera for
// colour, depth, G-buffer and output (registered, full resolution, intrinsics k = fx fy cx cy
// in pixels), exposure 1 and the runtime's default virtual-behind-real tolerance.
#pragma once
#include <glm/glm.hpp>

#include "common/frame_constants.glsl"

namespace mrgi::test {

inline shader::FrameConstants pinhole_frame_constants(const glm::mat4& camera_to_world, glm::vec4 k,
                                                      int width, int height, float depth_scale) {
  shader::FrameConstants fc{};
  fc.camera_to_world = camera_to_world;
  fc.world_to_camera = glm::inverse(camera_to_world);
  fc.camera_world = glm::vec4(glm::vec3(camera_to_world[3]), 1.0f);
  fc.internal_k = fc.output_k = fc.color_k = fc.depth_k = k;
  fc.internal_output_size = glm::ivec4(width, height, width, height);
  fc.color_depth_size = glm::ivec4(width, height, width, height);
  fc.camera = glm::vec4(depth_scale, 1.0f, 0.02f, 0.0f);
  return fc;
}

}  // namespace mrgi::test
