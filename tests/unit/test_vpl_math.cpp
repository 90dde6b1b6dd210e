// The VPL and paraboloid-map math (shaders/shared/vpl_math.h) on the CPU: the same functions
// the VPL, ISM and dir shaders run.
#include <gtest/gtest.h>

#include <cmath>

#include "shared/vpl_math.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

TEST(VplMath, HaltonIsTheRadicalInverse) {
  EXPECT_FLOAT_EQ(halton(0, 2), 0.0f);
  EXPECT_FLOAT_EQ(halton(1, 2), 0.5f);
  EXPECT_FLOAT_EQ(halton(2, 2), 0.25f);
  EXPECT_FLOAT_EQ(halton(3, 2), 0.75f);
  EXPECT_FLOAT_EQ(halton(1, 3), 1.0f / 3.0f);
  EXPECT_FLOAT_EQ(halton(5, 3), 7.0f / 9.0f);  // 5 = 12 in base 3 -> 0.21 = 2/3 + 1/9
  // Stratified: the first 2^k values of base 2 hit every interval of width 2^-k once.
  int hits[16] = {};
  for (uint i = 0; i < 16; ++i) ++hits[int(halton(i, 2) * 16.0f)];
  for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(VplMath, TangentFrameIsOrthonormalForEveryNormal) {
  for (int k = 0; k < 200; ++k) {
    const double y = 1.0 - 2.0 * (k + 0.5) / 200, r = std::sqrt(1.0 - y * y), phi = 2.39996 * k;
    const vec3 n(float(r * std::cos(phi)), float(r * std::sin(phi)), float(y));
    const vec3 t = frame_tangent(n), b = frame_bitangent(n);
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(b), 1.0f, 1e-5f);
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(glm::cross(t, b), n), 1.0f, 1e-5f);  // right-handed
  }
}

TEST(VplMath, ParaboloidMapsTheHemisphereOntoTheDiskAndBack) {
  const vec3 n = glm::normalize(vec3(0.3f, -0.5f, 0.8f));
  EXPECT_NEAR(glm::length(paraboloid_uv(n, n)), 0.0f, 1e-6f);  // the normal: the centre
  for (int k = 0; k < 100; ++k) {
    const vec2 uv(0.9f * float(std::cos(k * 0.7)) * float(k) / 100.0f, 0.9f * float(std::sin(k * 0.7)) * float(k) / 100.0f);
    const vec3 w = paraboloid_direction(uv, n);
    EXPECT_NEAR(glm::length(w), 1.0f, 1e-5f);
    EXPECT_GE(dot(w, n), -1e-6f);
    const vec2 back = paraboloid_uv(w, n);
    EXPECT_NEAR(back.x, uv.x, 1e-5f);
    EXPECT_NEAR(back.y, uv.y, 1e-5f);
  }
  EXPECT_EQ(paraboloid_uv(-n, n), vec2(2.0f));  // behind: outside the disk
}

TEST(VplMath, ParaboloidTexelsTileTheHemisphere) {
  // The texels inside the disk sum to the hemisphere's 2 pi sr.
  const int size = 256;
  double sum = 0.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const vec2 uv((x + 0.5f) / size * 2.0f - 1.0f, (y + 0.5f) / size * 2.0f - 1.0f);
      if (dot(uv, uv) <= 1.0f) sum += paraboloid_texel_solid_angle(uv, float(size));
    }
  EXPECT_NEAR(sum, 2.0 * kPi, 0.01 * 2.0 * kPi);
}

TEST(VplMath, IrradianceIsACosineEmitterOverDistanceSquared) {
  // Straight above, facing each other, 2 m: E = P / pi / 4.
  const vec3 q(0.0f), nq(0.0f, 1.0f, 0.0f), p(0.0f, 2.0f, 0.0f), np(0.0f, -1.0f, 0.0f);
  EXPECT_NEAR(vpl_irradiance(p, np, q, nq, 10.0f, 0.01f), 10.0 / kPi / 4.0, 1e-5);
  // 60 degrees off the VPL's normal, receiver facing it: a factor cos 60 = 0.5.
  const vec3 w(std::sin(kPi / 3), std::cos(kPi / 3), 0.0f);
  EXPECT_NEAR(vpl_irradiance(2.0f * w, -w, q, nq, 10.0f, 0.01f), 0.5 * 10.0 / kPi / 4.0, 1e-5);
  // Behind the VPL or facing away: nothing.
  EXPECT_EQ(vpl_irradiance(vec3(0.0f, -2.0f, 0.0f), nq, q, nq, 10.0f, 0.01f), 0.0f);
  EXPECT_EQ(vpl_irradiance(p, -np, q, nq, 10.0f, 0.01f), 0.0f);
  // Bounded next to it: at 1 mm with a 0.1 m clamp, as at 0.1 m.
  EXPECT_NEAR(vpl_irradiance(vec3(0.0f, 0.001f, 0.0f), np, q, nq, 1.0f, 0.1f), 1.0 / kPi / 0.01, 1e-3);
  EXPECT_EQ(vpl_irradiance(q, np, q, nq, 1.0f, 0.1f), 0.0f);  // on it: 0, not NaN
}

}  // namespace
