// The estimate in the shapes apps consume, checked against a known analytic light: a directional
// sun of irradiance E from direction d plus a uniform sky of radiance L.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "light/sh_tools.h"
#include "mrgi/light_estimate.h"

namespace {
using namespace mrgi;
using namespace mrgi::light;

struct Analytic {
  glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  glm::dvec3 sun{2.0, 1.8, 1.5};
  glm::dvec3 sky{0.1, 0.15, 0.3};
  LightEstimate estimate() const {
    ShRgb l = sh_directional_light(d, sun);
    l[0] += sky * std::sqrt(4.0 * kPi);  // Y00 = 1 / sqrt(4 pi)
    LightEstimate e;
    fill_light_estimate(l, kMaxShBands, e);
    e.valid = true;
    e.confidence = 1.0f;
    return e;
  }
  // Irradiance of the 3-band projection (what 9 coefficients can hold) at normal n.
  glm::dvec3 irradiance(const glm::dvec3& n) const {
    return sh_irradiance(sh_directional_light(d, sun), glm::vec3(n)) + kPi * sky;
  }
};

TEST(EnvironmentalHdr, MainLightAndAmbientOfAKnownLight) {
  const Analytic a;
  auto hdr = to_environmental_hdr(a.estimate(), 16);
  ASSERT_TRUE(hdr.ok()) << hdr.error().message;
  EXPECT_TRUE(hdr->valid);
  const glm::dvec3 dir(hdr->main_light_direction[0], hdr->main_light_direction[1], hdr->main_light_direction[2]);
  EXPECT_GT(glm::dot(dir, a.d), std::cos(0.5 * kPi / 180.0));  // within half a degree
  // A pure directional light plus a uniform ambient: the main light carries exactly the sun.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(hdr->main_light_intensity[size_t(c)], a.sun[c], 1e-3 * a.sun[c]);
  // The 27 coefficients are the radiance SH, coefficient-major.
  const ShRgb l = [&] {
    ShRgb x = sh_directional_light(a.d, a.sun);
    x[0] += a.sky * std::sqrt(4.0 * kPi);
    return x;
  }();
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(hdr->ambient_sh[size_t(3 * i + c)], l[size_t(i)][c], 1e-5);
  // The cubemap: 6 faces of 16 x 16; the brightest texel looks towards the sun, and every texel
  // is the SH radiance in its direction.
  ASSERT_EQ(hdr->face_size, 16);
  double best = -1.0;
  glm::dvec3 best_dir(0.0);
  for (int f = 0; f < 6; ++f) {
    ASSERT_EQ(hdr->cubemap[size_t(f)].width, 16);
    for (int v = 0; v < 16; ++v)
      for (int u = 0; u < 16; ++u) {
        const float* t = hdr->cubemap[size_t(f)].at(u, v);
        EXPECT_GE(t[0], 0.0f);
        if (t[1] > best) {
          best = t[1];
          // OpenGL face directions (see app_formats.cpp cube_direction).
          const double s = 2.0 * (u + 0.5) / 16 - 1.0, tt = 2.0 * (v + 0.5) / 16 - 1.0;
          const glm::dvec3 dirs[6] = {{1, -tt, -s}, {-1, -tt, s}, {s, 1, tt}, {s, -1, -tt}, {s, -tt, 1}, {-s, -tt, -1}};
          best_dir = glm::normalize(dirs[f]);
        }
      }
  }
  EXPECT_GT(glm::dot(best_dir, a.d), std::cos(10.0 * kPi / 180.0));  // within a texel or two
  EXPECT_FALSE(to_environmental_hdr(a.estimate(), 300).ok());
  EXPECT_FALSE(to_environmental_hdr(a.estimate(), 16, 1.5f).ok());
  EXPECT_FALSE(to_environmental_hdr(a.estimate(), 16, std::nanf("")).ok());
  auto no_cube = to_environmental_hdr(a.estimate(), 0);
  ASSERT_TRUE(no_cube.ok());
  EXPECT_TRUE(no_cube->cubemap[0].empty());
}

TEST(EnvironmentalHdr, ValidOnceTheConfidenceSaysSo) {
  const Analytic a;
  LightEstimate e = a.estimate();
  e.confidence = 2.0f / 16.0f;  // one flat surface in view
  auto low = to_environmental_hdr(e, 0);
  ASSERT_TRUE(low.ok());
  EXPECT_FALSE(low->valid);
  EXPECT_TRUE(to_environmental_hdr(e, 0, 0.0f)->valid) << "an app may take every estimate";
  e.confidence = kEnvironmentalHdrMinConfidence;
  EXPECT_TRUE(to_environmental_hdr(e, 0)->valid);
  e.valid = false;
  EXPECT_FALSE(to_environmental_hdr(e, 0, 0.0f)->valid) << "no estimate is never valid";
}

TEST(FilamentIrradiance, ShaderPolynomialGivesIrradianceOverPi) {
  const Analytic a;
  const auto sh = to_filament_irradiance(a.estimate());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 100; ++k) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    const double x = n.x, y = n.y, z = n.z;
    const double poly[9] = {1.0, y, z, x, y * x, y * z, 3.0 * z * z - 1.0, z * x, x * x - y * y};
    const glm::dvec3 expected = glm::max(a.irradiance(n), glm::dvec3(0.0)) / kPi;
    for (int c = 0; c < 3; ++c) {
      double f = 0.0;
      for (int i = 0; i < 9; ++i) f += double(sh[size_t(i)][size_t(c)]) * poly[i];
      EXPECT_NEAR(std::max(f, 0.0), expected[c], 1e-4) << "normal " << x << " " << y << " " << z;
    }
  }
  // A uniform sky alone: sh[0] is its radiance (E / pi = L), the rest 0.
  LightEstimate sky;
  ShRgb l{};
  l[0] = a.sky * std::sqrt(4.0 * kPi);
  fill_light_estimate(l, kMaxShBands, sky);
  const auto s2 = to_filament_irradiance(sky);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(s2[0][size_t(c)], a.sky[c], 1e-6);
}

}  // namespace
