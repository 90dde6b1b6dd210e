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

}  // namespace mrgi::runtime_detail
