#include "runtime/influence.h"

#include <array>

namespace mrgi::runtime {

bool virtual_influence_in_view(const InfluenceQuery& q, const std::vector<LightDesc>& lights) {
  for (const LightDesc& l : lights)
    if (!l.real) return true;
  const glm::dmat4 world_to_camera = glm::inverse(q.camera_to_world);
  const glm::dvec3 lo = q.box_min - q.margin_m, hi = q.box_max + q.margin_m;
  std::array<glm::dvec3, 8> corners_world, corners;
  for (int i = 0; i < 8; ++i) {
    corners_world[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    corners[i] = glm::dvec3(world_to_camera * glm::dvec4(corners_world[i], 1.0));
  }
  // Directions in which the hull extends to infinity (the shadow volumes), in camera space.
  std::vector<glm::dvec3> directions;
  const glm::dmat3 rot(world_to_camera);
  for (const LightDesc& l : lights) {
    if (l.type == LightType::Directional) {
      directions.push_back(rot * glm::dvec3(l.direction));
    } else {
      for (const glm::dvec3& c : corners_world) directions.push_back(rot * (c - glm::dvec3(l.position)));
    }
  }
  // Frustum planes through the camera centre, inside where n . x >= 0 (pixel edges -0.5 and
  // size - 0.5, so the test agrees with what the rasteriser covers), plus the plane z = 0.
  const Intrinsics& k = q.camera;
  const std::array<glm::dvec3, 5> planes = {
      glm::dvec3(k.fx, 0.0, k.cx + 0.5), glm::dvec3(-k.fx, 0.0, k.width - 0.5 - k.cx),
      glm::dvec3(0.0, k.fy, k.cy + 0.5), glm::dvec3(0.0, -k.fy, k.height - 0.5 - k.cy),
      glm::dvec3(0.0, 0.0, 1.0)};
  for (const glm::dvec3& n : planes) {
    bool outside = true;
    for (const glm::dvec3& c : corners) outside = outside && glm::dot(n, c) < 0.0;
    for (const glm::dvec3& d : directions) outside = outside && glm::dot(n, d) <= 0.0;
    if (outside) return false;
  }
  return true;
}

}  // namespace mrgi::runtime
