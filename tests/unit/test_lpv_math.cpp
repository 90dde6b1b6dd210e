// The light propagation volume math (shaders/shared/lpv_math.h) on the CPU: the same functions
// the injection and propagation shaders run.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shared/lpv_math.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

glm::vec3 fib(int k, int n) {
  const double y = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(std::max(0.0, 1.0 - y * y));
  const double phi = kPi * (3.0 - std::sqrt(5.0)) * k;
  return glm::vec3(float(r * std::cos(phi)), float(y), float(r * std::sin(phi)));
}

TEST(LpvMath, Basis4IsTheFirstBandsOfBasis16) {
  for (int k = 0; k < 50; ++k) {
    const vec3 d = fib(k, 50);
    const vec4 a = sh_basis4(d), b = sh_basis16(d).c0;
    for (int i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(a[i], b[i]);
  }
}

TEST(LpvMath, SolidAnglesAreTheExactFaceAngles) {
  EXPECT_NEAR(LPV_SOLID_ANGLE_FRONT, 4.0 * std::asin(0.1), 1e-7);
  // Far face + 4 side faces = what the whole neighbour cell subtends = its near face, 2 pi / 3.
  EXPECT_NEAR(LPV_SOLID_ANGLE_FRONT + 4.0 * LPV_SOLID_ANGLE_SIDE, 2.0 * kPi / 3.0, 1e-6);
}

TEST(LpvMath, CosineLobeIsTheProjectionOfTheClampedCosine) {
  // Project max(0, n . w) onto SH2 by quadrature and compare; its integral over the sphere is pi.
  const vec3 n = normalize(vec3(0.3f, -0.5f, 0.8f));
  const int count = 20000;
  glm::dvec4 proj(0.0);
  for (int k = 0; k < count; ++k) {
    const vec3 w = fib(k, count);
    proj += glm::dvec4(sh_basis4(w)) * double(std::max(0.0f, dot(n, w))) * (4.0 * kPi / count);
  }
  const vec4 lobe = sh4_cosine_lobe(n);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(lobe[i], proj[i], 2e-3) << i;
  EXPECT_NEAR(sh4_total_flux(lobe), kPi, 1e-5);
  EXPECT_NEAR(sh4_total_flux(lpv_vpl_intensity(n, 2.5f)), 2.5, 1e-5);  // a VPL emits its flux
}

// The 6 cells around a source gather from it (each sees it at the opposite axis).
float flux_after_one_step(vec4 source, float damping) {
  float total = 0.0f;
  for (int k = 0; k < 6; ++k) total += sh4_total_flux(lpv_gather_from(source, vec4(0.0f), k, damping));
  return total;
}

TEST(LpvMath, PropagationConservesFluxOfAnIsotropicCell) {
  const vec4 iso(1.0f, 0.0f, 0.0f, 0.0f);
  EXPECT_NEAR(flux_after_one_step(iso, 0.0f), sh4_total_flux(iso), 1e-5);
}

TEST(LpvMath, PropagationFollowsADirectionalLobe) {
  // A VPL facing +x: the cell on +x (which sees the source at its -x, k = 1) gets the most, the
  // cell on -x nothing, and less flux leaves in total than an isotropic cell would send (the
  // lobe's back is clamped in the faces' directions, its SH2 ring is not).
  const vec4 vpl = lpv_vpl_intensity(vec3(1.0f, 0.0f, 0.0f), 1.0f);
  const float plus_x = sh4_total_flux(lpv_gather_from(vpl, vec4(0.0f), 1, 0.0f));
  const float minus_x = sh4_total_flux(lpv_gather_from(vpl, vec4(0.0f), 0, 0.0f));
  const float plus_y = sh4_total_flux(lpv_gather_from(vpl, vec4(0.0f), 3, 0.0f));
  EXPECT_GT(plus_x, 2.0f * plus_y);
  EXPECT_GT(plus_y, minus_x);
  EXPECT_NEAR(flux_after_one_step(vpl, 0.0f), 1.0f, 0.02f);
  // What the +x cell re-emits leans along +x.
  const vec4 next = lpv_gather_from(vpl, vec4(0.0f), 1, 0.0f);
  EXPECT_GT(sh4_eval(next, vec3(1, 0, 0)), 2.0f * sh4_eval(next, vec3(-1, 0, 0)));
}

TEST(LpvMath, NegativeFluxIsDampedAtStepsOnly) {
  const vec4 shadow = lpv_vpl_intensity(vec3(0.0f, -1.0f, 0.0f), -1.0f);  // antiradiance, facing down
  // Into an empty cell (a step): damped by 1 / (1 + strength); positive flux never.
  const vec4 undamped = lpv_gather_from(shadow, vec4(0.0f), 2, 0.0f);  // the cell below (k = +y side)
  const vec4 damped = lpv_gather_from(shadow, vec4(0.0f), 2, 1.0f);
  EXPECT_LT(sh4_total_flux(undamped), 0.0f);
  EXPECT_NEAR(sh4_total_flux(damped), 0.5f * sh4_total_flux(undamped), 1e-4);
  const vec4 light = shadow * -1.0f;
  EXPECT_FLOAT_EQ(sh4_total_flux(lpv_gather_from(light, vec4(0.0f), 2, 1.0f)),
                  sh4_total_flux(lpv_gather_from(light, vec4(0.0f), 2, 0.0f)));
  // Into a cell that already holds the same value (a smooth field): not damped.
  const vec4 smooth = lpv_gather_from(shadow, shadow, 2, 1.0f);
  EXPECT_NEAR(sh4_total_flux(smooth), sh4_total_flux(undamped), 1e-5);
  EXPECT_FLOAT_EQ(lpv_negative_damping(-1.0f, 0.0f, 0.0f), 1.0f);
}

TEST(LpvMath, IrradianceOfAFacingLobe) {
  // A cell whose intensity is a diffuse emitter of flux 1 facing +y, seen by a surface facing -y
  // (the light comes at it): E = (lobe(y) . lobe(y)) / pi / s^2 = (pi/4 + pi/3) / pi / s^2 =
  // 7 / 12 / s^2. A surface facing +y gets (pi/4 - pi/3) / pi / s^2 = -1 / 12 / s^2: SH2's back
  // lobe, a seventh of the front (the known ringing of 2-band LPVs).
  const vec4 i = lpv_vpl_intensity(vec3(0.0f, 1.0f, 0.0f), 1.0f);
  const float facing = lpv_irradiance(i, vec3(0.0f, -1.0f, 0.0f), 0.5f);
  const float away = lpv_irradiance(i, vec3(0.0f, 1.0f, 0.0f), 0.5f);
  EXPECT_NEAR(facing, 7.0 / 12.0 / 0.25, 1e-5);
  EXPECT_NEAR(away, -1.0 / 12.0 / 0.25, 1e-5);
  EXPECT_NEAR(lpv_irradiance(i, vec3(0.0f, -1.0f, 0.0f), 1.0f) * 4.0f, facing, 1e-5);  // 1 / s^2
}

}  // namespace

namespace {
using namespace mrgi::shader;

// How far propagated light is from the truth: an isotropic point source of 1 W in a 33^3 volume,
// 32 steps, irradiance on the +x axis (surface facing the source) against 1 / (4 pi r^2). The
// gather is diffusive (each step re-emits cosine lobes), so the light lingers near the source
// and thins out with distance faster than 1 / r^2: measured 1.18, 1.85, 1.86, 1.66, 1.29 at 1-5
// cells, 0.64 at 7, 0.14 at 10 (cell 0.1 m). Pinned so a change of the propagation shows here.
TEST(LpvMath, PointSourceIrradianceAgainstTheInverseSquare) {
  const int n = 33;
  const float s = 0.1f;
  auto idx = [&](int x, int y, int z) { return size_t((z * n + y) * n + x); };
  std::vector<vec4> cur(size_t(n) * n * n, vec4(0.0f)), next(cur.size());
  cur[idx(16, 16, 16)] = vec4(1.0f / (4.0f * MRGI_PI) / 0.282094791773878f, 0.0f, 0.0f, 0.0f);
  std::vector<vec4> sum = cur;
  for (int step = 0; step < 32; ++step) {
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          vec4 acc(0.0f);
          for (int k = 0; k < 6; ++k) {
            const glm::ivec3 q = glm::ivec3(x, y, z) + glm::ivec3(lpv_axis(k));
            if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, glm::ivec3(n)))) continue;
            acc += lpv_gather_from(cur[idx(q.x, q.y, q.z)], cur[idx(x, y, z)], k, 0.0f);
          }
          next[idx(x, y, z)] = acc;
        }
    cur.swap(next);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += cur[i];
  }
  const float want[] = {1.183f, 1.848f, 1.863f, 1.662f, 1.293f};
  for (int d = 1; d <= 5; ++d) {
    const float truth = 1.0f / (4.0f * MRGI_PI * (d * s) * (d * s));
    EXPECT_NEAR(lpv_irradiance(sum[idx(16 + d, 16, 16)], vec3(-1.0f, 0.0f, 0.0f), s) / truth, want[d - 1], 0.01f) << d;
  }
}

}  // namespace
