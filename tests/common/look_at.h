// Camera-to-world of an OpenCV-convention camera (x right, y down, z forward) at `eye` looking at
// `target`, with `up` the world direction that appears up in the image. Shared by the tests that
// place cameras (path tracer, ssrt volume, ssrt GPU chain).
#pragma once
#include <glm/glm.hpp>

namespace mrgi::test {

inline glm::dmat4 opencv_look_at(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up) {
  const glm::dvec3 z = glm::normalize(target - eye);
  const glm::dvec3 x = glm::normalize(glm::cross(z, up));
  const glm::dvec3 y = glm::cross(z, x);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(x, 0.0);
  m[1] = glm::dvec4(y, 0.0);
  m[2] = glm::dvec4(z, 0.0);
  m[3] = glm::dvec4(eye, 1.0);
  return m;
}

}  // namespace mrgi::test
