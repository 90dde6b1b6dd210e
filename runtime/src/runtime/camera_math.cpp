#include "runtime/camera_math.h"

#include <cmath>

namespace mrgi::runtime_detail {

glm::mat4 opencv_projection(const Intrinsics& k, float near_m, float far_m) {
  const float w = float(k.width), h = float(k.height);
  glm::mat4 p(0.0f);  // glm: p[column][row]
  p[0][0] = 2.0f * float(k.fx) / w;
  p[1][1] = 2.0f * float(k.fy) / h;
  p[2][0] = 2.0f * (float(k.cx) + 0.5f) / w - 1.0f;
  p[2][1] = 2.0f * (float(k.cy) + 0.5f) / h - 1.0f;
  p[2][2] = far_m / (far_m - near_m);
  p[3][2] = -far_m * near_m / (far_m - near_m);
  p[2][3] = 1.0f;
  return p;
}

glm::vec3 environment_mean(const ImageRGBF& image, bool equirectangular) {
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < image.height; ++y) {
    const double row_w =
        equirectangular ? std::sin(M_PI * (double(y) + 0.5) / double(image.height)) : 1.0;
    for (int x = 0; x < image.width; ++x) {
      const float* t = image.at(x, y);
      glm::dvec3 c(t[0], t[1], t[2]);
      for (int i = 0; i < 3; ++i)
        if (!(c[i] >= 0.0) || std::isinf(c[i])) c[i] = 0.0;
      if (!equirectangular && c.x + c.y + c.z <= 0.0) continue;
      sum += c * row_w;
      weight += row_w;
    }
  }
  if (weight <= 0.0) return glm::vec3(0.0f);
  return glm::vec3(sum / weight);
}

}  // namespace mrgi::runtime_detail
