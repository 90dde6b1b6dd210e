#include "light/light_set_writer.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace mrgi::light {

void write_unshadowed_light_set(const light::Lighting& lighting, shader::LightSet& set) {
  set = shader::LightSet{};
  const int n = std::min<int>(int(lighting.lights.size()), MRGI_MAX_LIGHTS);
  set.count = glm::ivec4(n, lighting.ambient_is_residual ? 1 : 0, 0, 0);
  for (int i = 0; i < n; ++i) {
    const LightDesc& l = lighting.lights[size_t(i)];
    shader::ShadowLight& s = set.lights[i];
    const int type = l.type == LightType::Directional ? MRGI_LIGHT_DIRECTIONAL
                     : l.type == LightType::Spot      ? MRGI_LIGHT_SPOT
                                                      : MRGI_LIGHT_POINT;
    s.position_type = glm::vec4(l.position, float(type));
    s.direction_real = glm::vec4(glm::normalize(l.direction), l.real ? 1.0f : 0.0f);
    s.intensity = glm::vec4(l.color * l.intensity, 0.0f);
    s.cone = glm::vec4(std::cos(glm::radians(l.inner_angle_deg)), std::cos(glm::radians(l.outer_angle_deg)), 0.0f, 0.0f);
    s.layers = glm::ivec4(-1, -1, 0, 0);
  }
  light::ShRgb both;
  for (int i = 0; i < light::kMaxShCoeffs; ++i)
    both[size_t(i)] = lighting.ambient_real[size_t(i)] + lighting.ambient_virtual[size_t(i)];
  const auto rv = light::irradiance_matrices(both);
  const auto r = light::irradiance_matrices(lighting.ambient_real);
  set.ambient_rv = {rv[0], rv[1], rv[2]};
  set.ambient_r = {r[0], r[1], r[2]};
}

}  // namespace mrgi::light
