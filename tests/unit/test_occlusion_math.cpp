// The environment-occlusion math (shaders/shared/occlusion_math.h) on the CPU, against numeric
// integration over the sphere: the same functions environment_occlusion.comp runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "light/sh_tools.h"
#include "shading/environment_occlusion.h"
#include "shared/occlusion_math.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

// Fraction of the cosine-weighted hemisphere around +z that a sphere of sin(alpha) = s at
// polar angle theta from +z covers, by a fine product quadrature (theta, phi) over the upper
// hemisphere.
double numeric_form_factor(double theta, double sin_alpha) {
  const glm::dvec3 c(std::sin(theta), 0.0, std::cos(theta));
  const double cos_alpha = std::sqrt(1.0 - sin_alpha * sin_alpha);
  const int nt = 1200, np = 2400;
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) / nt * (kPi / 2.0);
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) / np * 2.0 * kPi;
      const glm::dvec3 w(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
      if (glm::dot(w, c) >= cos_alpha) sum += std::cos(t) * std::sin(t);
    }
  }
  return sum * (kPi / 2.0 / nt) * (2.0 * kPi / np) / kPi;
}

TEST(OcclusionMath, SphereFormFactorAboveTheHorizonIsSinSquaredCos) {
  for (double s : {0.1, 0.3, 0.6})
    for (double theta : {0.0, 0.4, 0.8}) {
      if (std::cos(theta) < s) continue;
      EXPECT_NEAR(sphere_form_factor(float(std::cos(theta)), float(s * s)), s * s * std::cos(theta), 1e-6);
    }
}

TEST(OcclusionMath, SphereFormFactorMatchesIntegrationAcrossTheHorizon) {
  // Spheres straddling the horizon (the floor beside an object), and the two clean cases.
  const double cases[][2] = {{1.3, 0.5}, {1.5708, 0.5}, {1.8, 0.5}, {1.4, 0.9}, {1.9, 0.8}, {0.3, 0.4}, {2.6, 0.3}};
  for (const auto& c : cases) {
    const double expected = numeric_form_factor(c[0], c[1]);
    const float got = sphere_form_factor(float(std::cos(c[0])), float(c[1] * c[1]));
    EXPECT_NEAR(got, expected, 2e-3 + 0.01 * expected) << "theta " << c[0] << " sin alpha " << c[1];
  }
  // Below the horizon entirely: nothing.
  EXPECT_EQ(sphere_form_factor(-0.9f, 0.1f), 0.0f);
}

TEST(OcclusionMath, SphereFormFactorIsFiniteAtTheLimits) {
  for (float c : {-1.0f, -0.5f, 0.0f, 1e-7f, 0.5f, 1.0f})
    for (float s2 : {0.0f, 1e-9f, 0.5f, 0.9999f, 1.0f, 2.0f}) {
      const float f = sphere_form_factor(c, s2);
      EXPECT_TRUE(std::isfinite(f)) << c << " " << s2;
      EXPECT_GE(f, 0.0f);
      EXPECT_LE(f, 1.0f);
    }
}

// Mean of SH16 radiance over a cap, numerically.
glm::dvec3 numeric_cap_mean(const SH16 ch[3], glm::dvec3 axis, double cos_alpha) {
  const int n = 400000;
  glm::dvec3 sum(0.0);
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const double y = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double phi = kPi * (3.0 - std::sqrt(5.0)) * k;
    const glm::dvec3 w(r * std::cos(phi), y, r * std::sin(phi));
    if (glm::dot(w, axis) < cos_alpha) continue;
    const SH16 b = sh_basis16(glm::vec3(w));
    sum += glm::dvec3(sh_dot(ch[0], b), sh_dot(ch[1], b), sh_dot(ch[2], b));
    ++count;
  }
  return sum / double(count);
}

TEST(OcclusionMath, CapMeanRadianceMatchesIntegration) {
  // A positive radiance with every band present (a sky: bright above, a sun-ish lobe).
  SH16 ch[3];
  for (int c = 0; c < 3; ++c) {
    ch[c].c0 = vec4(2.0f + c, 0.8f, 0.5f - 0.1f * c, 0.3f);
    ch[c].c1 = vec4(0.2f, -0.15f, 0.25f, 0.1f);
    ch[c].c2 = vec4(-0.1f, 0.05f, 0.08f, -0.04f);
    ch[c].c3 = vec4(0.03f, 0.06f, -0.02f, 0.05f);
  }
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.8, -0.4));
  for (double alpha_deg : {5.0, 25.0, 60.0, 90.0}) {
    const double ca = std::cos(alpha_deg * kPi / 180.0);
    const glm::dvec3 expected = numeric_cap_mean(ch, axis, ca);
    const vec3 got = sh_cap_mean_radiance(ch[0], ch[1], ch[2], glm::vec3(axis), float(ca));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 2e-3 * (1.0 + std::abs(expected[c]))) << alpha_deg;
  }
  // The band factors of a hemisphere and of a point.
  const vec4 h = sh_cap_band_factors(0.0f), p = sh_cap_band_factors(1.0f);
  EXPECT_NEAR(h.y, 0.5f, 1e-6f);
  EXPECT_NEAR(h.z, 0.0f, 1e-6f);
  EXPECT_NEAR(h.w, -0.125f, 1e-6f);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(p[i], 1.0f, 1e-4f);
}

// Solid angle two caps share, by a product quadrature over the smaller cap (around +z), cap b's
// centre `theta` away in the xz plane.
double numeric_cap_overlap(double theta, double a, double b) {
  const double small = std::min(a, b), big = std::max(a, b);
  const glm::dvec3 c(std::sin(theta), 0.0, std::cos(theta));
  const int nt = 1500, np = 3000;
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) / nt * small;
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) / np * 2.0 * kPi;
      const glm::dvec3 w(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
      if (glm::dot(w, c) >= std::cos(big)) sum += std::sin(t);
    }
  }
  return sum * (small / nt) * (2.0 * kPi / np);
}

TEST(OcclusionMath, CapOverlapMatchesIntegration) {
  // {theta, a, b}: partial overlaps of small and large caps, a cap nearly inside the other, and
  // two hemispheres.
  const double cases[][3] = {{0.3, 0.2, 0.25}, {0.5, 0.1, 0.45}, {0.2, 0.4, 0.4}, {1.0, 0.8, 0.5},
                             {0.38, 0.1, 0.3}, {0.7, 1.5707, 1.5707}, {0.05, 0.02, 0.04},
                             {0.12, 0.09, 0.1}, {0.15, 0.1, 0.11}};  // either side of the small-cap form
  for (const auto& c : cases) {
    const double expected = numeric_cap_overlap(c[0], c[1], c[2]);
    const float got = cap_overlap_solid_angle(float(c[0]), float(c[1]), float(c[2]));
    EXPECT_NEAR(got, expected, 1e-3 * (2.0 * kPi * (1.0 - std::cos(std::min(c[1], c[2])))) + 1e-6)
        << "theta " << c[0] << " a " << c[1] << " b " << c[2];
    // Symmetric in the two caps.
    EXPECT_NEAR(got, cap_overlap_solid_angle(float(c[0]), float(c[2]), float(c[1])), 1e-5 + 1e-4 * got);
  }
}

TEST(OcclusionMath, CapOverlapLimits) {
  // Apart: nothing; one inside the other: the smaller cap whole; two hemispheres theta apart:
  // 2 (pi - theta).
  EXPECT_EQ(cap_overlap_solid_angle(0.5f, 0.2f, 0.25f), 0.0f);
  const float inside = cap_overlap_solid_angle(0.1f, 0.1f, 0.3f);
  EXPECT_NEAR(inside, 2.0 * kPi * (1.0 - std::cos(0.1)), 1e-6);
  EXPECT_NEAR(cap_overlap_solid_angle(0.7f, 1.5707963f, 1.5707963f), 2.0 * (kPi - 0.7), 1e-4);
  // Grows as the caps come together, never beyond the smaller cap.
  float last = -1.0f;
  for (int i = 40; i >= 0; --i) {
    const float v = cap_overlap_solid_angle(0.6f * float(i) / 40.0f, 0.2f, 0.35f);
    EXPECT_TRUE(std::isfinite(v));
    EXPECT_GE(v, last - 1e-6f);
    EXPECT_LE(v, 2.0 * kPi * (1.0 - std::cos(0.2)) + 1e-6);
    last = v;
  }
  EXPECT_EQ(cap_overlap_solid_angle(0.3f, 0.0f, 0.4f), 0.0f);
}

// The pass's fraction of a region's cone a proxy covers (cap_covered_fraction) against the exact
// lune over half-angles 1-80 degrees and every separation where they meet: within 0.11 of the
// region's solid angle everywhere, 0.025 on average; exact at the two ends.
TEST(OcclusionMath, CapCoveredFractionFollowsTheExactOverlap) {
  double worst = 0.0, sum = 0.0;
  int n = 0;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 25; ++j) {
      const double a = 0.02 + 1.38 * i / 29.0, b = 0.05 + 1.15 * j / 24.0;
      const double region = 2.0 * kPi * (1.0 - std::cos(b));
      for (int k = 0; k < 40; ++k) {
        const double theta = (a + b) * k / 39.0;
        const double exact = cap_overlap_solid_angle(float(theta), float(a), float(b)) / region;
        const double got = cap_covered_fraction(float(theta), float(a), float(b));
        worst = std::max(worst, std::abs(got - exact));
        sum += std::abs(got - exact);
        ++n;
      }
      EXPECT_NEAR(cap_covered_fraction(float(a + b + 0.01), float(a), float(b)), 0.0f, 1e-6f);
      EXPECT_NEAR(cap_covered_fraction(float(std::abs(a - b) * 0.5), float(a), float(b)),
                  std::min(1.0, (1.0 - std::cos(a)) / (1.0 - std::cos(b))), 1e-4);
    }
  EXPECT_LT(worst, 0.11);
  EXPECT_LT(sum / n, 0.025);
}

TEST(OcclusionMath, DisjointSpheresUnderAUniformSkyBlockTheirSolidAngle) {
  // Two small spheres far apart above a point, uniform sky of radiance 2: the blocked irradiance
  // is about 2 x pi x (f1 + f2) (the product form differs from the sum only by f1 f2).
  const float f1 = sphere_form_factor(0.9f, 0.01f), f2 = sphere_form_factor(0.5f, 0.04f);
  SphereOcclusion o = sphere_occlusion_none();
  o = sphere_occlusion_add(o, f1, vec3(2.0f));
  o = sphere_occlusion_add(o, f2, vec3(2.0f));
  const vec3 e = sphere_occlusion_irradiance(o);
  EXPECT_NEAR(e.x, 2.0 * kPi * (1.0 - (1.0 - f1) * (1.0 - f2)), 1e-5);
  EXPECT_NEAR(e.x, 2.0 * kPi * (f1 + f2), 2.0 * kPi * f1 * f2 + 1e-5);
  // Nothing added: nothing blocked.
  EXPECT_EQ(sphere_occlusion_irradiance(sphere_occlusion_none()).x, 0.0f);
}

// The near-field march starts past the sphere's far side, grows monotonically and ends at the
// reach; a reach inside the object marches nowhere past its far side.
TEST(OcclusionMath, NearFieldMarchRunsFromTheFarSideToTheReach) {
  const int steps = 8;
  float last = 0.6f;
  for (int k = 0; k < steps; ++k) {
    const float t = near_field_march_t(0.6f, 3.0f, k, steps);
    EXPECT_GT(t, last) << "step " << k;
    last = t;
  }
  EXPECT_NEAR(last, 3.0f, 1e-5f);
  // Denser near the object: the first half of the steps covers a quarter of the way.
  EXPECT_NEAR(near_field_march_t(0.6f, 3.0f, steps / 2 - 1, steps), 0.6f + 2.4f * 0.25f, 1e-5f);
  EXPECT_NEAR(near_field_march_t(0.6f, 0.1f, steps - 1, steps), 0.6f, 1e-6f);
}

}  // namespace

// The Lambert sphere's phase against the mean radiance of a diffuse unit sphere's visible disk,
// integrated over its surface (radiance max(n.l, 0) / pi at unit irradiance and albedo, weighted
// by the projected area n.v).
TEST(OcclusionMath, LambertSpherePhaseMatchesTheVisibleDiskIntegrated) {
  for (double a_deg : {0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0}) {
    const double a = a_deg * kPi / 180.0;
    const glm::dvec3 l(std::sin(a), 0.0, std::cos(a)), v(0.0, 0.0, 1.0);
    const int nt = 600, np = 1200;
    double lit = 0.0, area = 0.0;
    for (int i = 0; i < nt; ++i) {
      const double t = (i + 0.5) / nt * kPi;
      for (int j = 0; j < np; ++j) {
        const double p = (j + 0.5) / np * 2.0 * kPi;
        const glm::dvec3 n(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
        const double proj = std::max(glm::dot(n, v), 0.0) * std::sin(t);
        lit += std::max(glm::dot(n, l), 0.0) / kPi * proj;
        area += proj;
      }
    }
    EXPECT_NEAR(lambert_sphere_phase(float(std::cos(a))) / kPi, lit / area, 2e-4) << a_deg << " degrees";
  }
}

// A unit sphere tessellated finely (latitude-longitude), as positions and triangle indices.
void tessellated_sphere(std::vector<glm::vec3>& positions, std::vector<uint32_t>& indices) {
  const int rings = 48, segments = 96;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double t = kPi * i / rings, p = 2.0 * kPi * j / segments;
      positions.emplace_back(std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
      for (uint32_t k : {a, a + 1, b, a + 1, b + 1, b}) indices.push_back(k);
    }
}

// An axis-aligned box of half-extents h, outward-facing triangles.
void box(const glm::vec3& h, std::vector<glm::vec3>& positions, std::vector<uint32_t>& indices) {
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      glm::vec3 n(0.0f), u(0.0f), v(0.0f);
      n[axis] = sign;
      u[(axis + 1) % 3] = 1.0f;
      v[(axis + 2) % 3] = 1.0f;
      if (sign < 0.0f) std::swap(u, v);  // keep the winding outward
      const uint32_t base = uint32_t(positions.size());
      for (glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)})
        positions.push_back(h * (n + c.x * u + c.y * v));
      for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) indices.push_back(base + k);
    }
}

// What a viewer in direction v sees of the patches lit by `lights` (the shader's sum).
glm::vec3 seen(const std::vector<mrgi::frame::OrientedPatch>& patches, const std::vector<mrgi::LightDesc>& lights,
               const glm::vec3& v) {
  glm::vec4 sum(0.0f);
  for (const auto& p : patches)
    sum += lit_patch_term(glm::vec4(p.normal, p.area), mrgi::shading::lit_patch_radiance(p, glm::vec3(0.0f), lights), v);
  return lit_object_radiance(sum);
}

mrgi::LightDesc sun_from(const glm::vec3& to_light, float irradiance) {
  mrgi::LightDesc sun;
  sun.type = mrgi::LightType::Directional;
  sun.direction = -glm::normalize(to_light);
  sun.intensity = irradiance;
  return sun;
}

// A box's six faces come out as six exact patches; lit from above, a viewer beside it sees only
// its unlit sides and one above it the lit top (albedo E / pi).
TEST(OcclusionMath, BoxPatchesShowTheLitTopFromAboveAndDarkSidesBeside) {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  box(glm::vec3(0.2f, 0.1f, 0.3f), positions, indices);
  const std::vector<glm::vec3> albedo(indices.size() / 3, glm::vec3(0.5f));
  const auto patches = mrgi::frame::cluster_surface_orientations(positions, indices, albedo, 8);
  ASSERT_EQ(patches.size(), 6u);
  float area = 0.0f;
  for (const auto& p : patches) {
    area += p.area;
    EXPECT_NEAR(std::max({std::abs(p.normal.x), std::abs(p.normal.y), std::abs(p.normal.z)}), 1.0f, 1e-5f);
    EXPECT_NEAR(p.albedo.x, 0.5f, 1e-5f);
  }
  EXPECT_NEAR(area, 2.0f * (0.4f * 0.2f + 0.2f * 0.6f + 0.4f * 0.6f), 1e-4f);
  const std::vector<mrgi::LightDesc> sun{sun_from(glm::vec3(0.0f, 1.0f, 0.0f), 4.0f)};
  EXPECT_NEAR(seen(patches, sun, glm::vec3(0.0f, 1.0f, 0.0f)).x, 0.5f * 4.0f / float(kPi), 1e-5f);
  EXPECT_NEAR(seen(patches, sun, glm::vec3(1.0f, 0.0f, 0.0f)).x, 0.0f, 1e-6f);
  EXPECT_NEAR(seen(patches, sun, glm::normalize(glm::vec3(1.0f, -0.3f, 0.5f))).x, 0.0f, 1e-6f);
}

// A sphere's surface in 8 patches, lit by one directional light, shows a viewer what the Lambert
// sphere's phase says within 0.1 albedo E / pi of the face-on 2/3 (measured: worst 0.084, mean
// 0.025; 8 orientations are a coarse quadrature of a smooth surface, worst at the terminator).
TEST(OcclusionMath, SpherePatchesFollowTheLambertSpherePhase) {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  tessellated_sphere(positions, indices);
  const std::vector<glm::vec3> albedo(indices.size() / 3, glm::vec3(1.0f));
  const auto patches = mrgi::frame::cluster_surface_orientations(positions, indices, albedo, 8);
  ASSERT_EQ(patches.size(), 8u);
  float area = 0.0f;
  for (const auto& p : patches) area += p.area;
  EXPECT_NEAR(area, 4.0f * float(kPi), 0.01f * 4.0f * float(kPi));
  const glm::vec3 to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
  const std::vector<mrgi::LightDesc> sun{sun_from(to_light, float(kPi))};  // albedo E / pi = 1
  double worst = 0.0, mean = 0.0;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const glm::vec3 v = glm::vec3(mrgi::light::fibonacci_direction(k, n));
    const double err = std::abs(double(seen(patches, sun, v).x) - double(lambert_sphere_phase(glm::dot(to_light, v))));
    worst = std::max(worst, err);
    mean += err / n;
  }
  EXPECT_LT(worst, 0.1) << "mean " << mean;
  EXPECT_LT(mean, 0.04) << "worst " << worst;
}

// A point lamp lights a patch by 1 / d^2 from the object's centre; a spot lights nothing outside
// its cone; a patch facing away gets nothing.
TEST(OcclusionMath, LitPatchFollowsTheLampsDistanceConeAndFacing) {
  mrgi::frame::OrientedPatch up;
  up.normal = glm::vec3(0.0f, 1.0f, 0.0f);
  up.area = 1.0f;
  up.albedo = glm::vec3(0.5f);
  mrgi::LightDesc lamp;
  lamp.type = mrgi::LightType::Point;
  lamp.position = glm::vec3(0.0f, 2.0f, 0.0f);
  lamp.intensity = 4.0f;
  EXPECT_NEAR(mrgi::shading::lit_patch_radiance(up, glm::vec3(0.0f), {lamp}).x, 0.5f * 4.0f / 4.0f / float(kPi), 1e-6f);
  lamp.position.y = 4.0f;
  EXPECT_NEAR(mrgi::shading::lit_patch_radiance(up, glm::vec3(0.0f), {lamp}).x, 0.5f * 4.0f / 16.0f / float(kPi), 1e-6f);
  mrgi::frame::OrientedPatch down = up;
  down.normal = -up.normal;
  EXPECT_EQ(mrgi::shading::lit_patch_radiance(down, glm::vec3(0.0f), {lamp}).x, 0.0f);
  lamp.type = mrgi::LightType::Spot;
  lamp.direction = glm::vec3(1.0f, 0.0f, 0.0f);  // pointing away from the object below it
  EXPECT_EQ(mrgi::shading::lit_patch_radiance(up, glm::vec3(0.0f), {lamp}).x, 0.0f);
}
