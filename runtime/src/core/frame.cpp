#include "mrgi/frame.h"

namespace mrgi {

Intrinsics Intrinsics::scaled_to(int w, int h) const {
  Intrinsics out = *this;
  const double sx = double(w) / width, sy = double(h) / height;
  out.width = w;
  out.height = h;
  out.fx = fx * sx;
  out.fy = fy * sy;
  // Pixel centres: a pixel's centre at (x + 0.5) scales with the image, so cx + 0.5 does too.
  out.cx = (cx + 0.5) * sx - 0.5;
  out.cy = (cy + 0.5) * sy - 0.5;
  return out;
}

glm::dmat4 Pose::matrix() const {
  glm::dmat4 m = glm::mat4_cast(glm::normalize(rotation));
  m[3] = glm::dvec4(translation, 1.0);
  return m;
}

}  // namespace mrgi
