// What a draw needs to choose a mesh's level of detail (MeshSet::draw), in a header
// of its own (glm only) so the CPU-only planners (shading/shadow_plan.h) can hold one.
#pragma once
#include <glm/glm.hpp>

namespace mrgi::frame {

// The camera centre (world) and the focal length in pixels of the image drawn; a range is drawn
// with the coarsest level whose error, projected at the range's nearest distance from the
// camera, stays within `max_error_px`.
struct LodView {
  glm::vec3 camera_world{0.0f};
  float focal_px = 0.0f;
  float max_error_px = 0.5f;
};

// An orthographic view (a directional lamp's map, `texel_m` metres a texel, looking along
// `travel`) as a LodView: an error of e metres covers e / texel_m texels anywhere, which is a
// perspective eye far away (distance D, focal D / texel_m).
inline constexpr float kOrthographicLodDistance = 1.0e4f;
inline LodView orthographic_lod_view(const glm::vec3& centre, const glm::vec3& travel, float texel_m, float max_error_px) {
  return {centre - travel * kOrthographicLodDistance, kOrthographicLodDistance / texel_m, max_error_px};
}

}  // namespace mrgi::frame
