// Importance sampling of an equirectangular environment (mapping in mrgi/reference/path_tracer.h)
// by a 2-D piecewise-constant distribution over luminance * sin(theta): a marginal over rows and
// one conditional per row (Pharr, Jakob & Humphreys, PBRT 3rd ed., 13.6.7 and 14.2.4).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/reference/path_tracer.h"

namespace mrgi::reference {

class EnvironmentSampler {
 public:
  EnvironmentSampler() = default;
  explicit EnvironmentSampler(const RefEnvironment& env);

  bool present() const { return width_ > 0; }
  // Radiance arriving from world direction d (unit), piecewise constant per pixel.
  glm::vec3 radiance(const glm::vec3& d) const;
  // Solid-angle pdf of sample() returning d.
  float pdf(const glm::vec3& d) const;
  // Draws a world direction; returns false when the map is black everywhere.
  bool sample(glm::vec2 u, glm::vec3* d, glm::vec3* radiance, float* pdf) const;

  // Equirectangular mapping of environment-space directions, shared with the fisheye sensor.
  static glm::vec2 direction_to_uv(const glm::vec3& d);
  static glm::vec3 uv_to_direction(glm::vec2 uv);

 private:
  int pixel_index(const glm::vec3& d_world, int* x, int* y) const;
  int width_ = 0, height_ = 0;
  std::vector<glm::vec3> radiance_;   // intensity applied
  std::vector<float> row_cdf_;        // height + 1
  std::vector<float> col_cdf_;        // height * (width + 1)
  std::vector<float> row_weight_;     // unnormalised row sums
  float total_ = 0.0f;
  glm::mat3 env_to_world_{1.0f}, world_to_env_{1.0f};
};

}  // namespace mrgi::reference
