// A sky for light-estimation tests: uniform radiance over the hemisphere above `up` and nothing
// below it (what a camera on a floor can be lit by), projected to SH by quadrature over a
// Fibonacci sphere.
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "light/sh_tools.h"

namespace mrgi::test {

inline void add_sh_sky(light::ShRgb& l, double radiance, const glm::dvec3& up = {0.0, 1.0, 0.0}) {
  constexpr int kDirections = 4000;
  constexpr double kPi = 3.14159265358979323846;
  for (int k = 0; k < kDirections; ++k) {
    const glm::dvec3 w = light::fibonacci_direction(k, kDirections);
    if (glm::dot(w, up) <= 0.0) continue;
    const light::ShVector b = light::sh_basis(glm::vec3(w));
    for (int i = 0; i < light::kMaxShCoeffs; ++i)
      l[i] += glm::dvec3(radiance * b[i] * 4.0 * kPi / kDirections);
  }
}

}  // namespace mrgi::test
