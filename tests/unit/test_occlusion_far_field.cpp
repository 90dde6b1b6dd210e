// An object's sphere proxies against the object itself (shaders/shared/occlusion_math.h
// far_field_scale), and the light the real surfaces round it stop reflecting
// (shading/environment_occlusion.h real_bounce_flux, occlusion_math.h real_bounce_loss): the
// form factors are checked against rays cast at the mesh's triangles, the fluxes against the
// closed forms of a cube under a uniform sky.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "frame/occluder_spheres.h"
#include "frame/surface_orientation.h"
#include "shading/environment_occlusion.h"
#include "shared/occlusion_math.h"
#include "test_meshes.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

using Mesh = mrgi::test::TestMesh;
Mesh box(glm::vec3 lo, glm::vec3 hi) { return mrgi::test::box_mesh(lo, hi); }
Mesh uv_sphere(float r) { return mrgi::test::uv_sphere_mesh(glm::vec3(0.0f), r, 16, 32); }

bool ray_hits(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-14) return false;
  const glm::dvec3 t = o - a;
  const double u = glm::dot(t, p) / det;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 q = glm::cross(t, e1);
  const double v = glm::dot(d, q) / det;
  return v >= 0.0 && u + v <= 1.0 && glm::dot(e2, q) / det > 0.0;
}

// The mesh's form factor seen from `o` with unit normal `n` facing it: rays spread uniformly
// over the cone bounding the mesh (half-angle from its bounding radius), cosine-weighted.
double mesh_form_factor(const Mesh& m, const glm::dvec3& o, const glm::dvec3& n, double bound) {
  const double dist = glm::length(o);
  const double cos_cone = std::sqrt(std::max(1.0 - bound * bound / (dist * dist), 0.0));
  const glm::dvec3 axis = -o / dist;
  const glm::dvec3 t = std::abs(axis.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(axis, t)), v = glm::cross(axis, u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const int rays = 6000;
  double sum = 0.0;
  for (int k = 0; k < rays; ++k) {
    const double cz = 1.0 - uni(rng) * (1.0 - cos_cone), sz = std::sqrt(1.0 - cz * cz), ph = 2.0 * kPi * uni(rng);
    const glm::dvec3 d = cz * axis + sz * (std::cos(ph) * u + std::sin(ph) * v);
    for (size_t q = 0; q + 2 < m.i.size(); q += 3)
      if (ray_hits(o, d, m.p[m.i[q]], m.p[m.i[q + 1]], m.p[m.i[q + 2]])) {
        sum += std::max(glm::dot(d, n), 0.0);
        break;
      }
  }
  return sum / rays * 2.0 * kPi * (1.0 - cos_cone) / kPi;
}

// Per view: the proxies' form factor (independent occluders, as the pass combines them) with and
// without the far-field scale, over the mesh's.
struct Ratios {
  double plain, scaled;
};
// An object's proxies as the pass gets them at load: spheres, oriented patches, the spheres'
// volume-weighted centre and reach, their disc area, and the mesh's bounding radius. Fitted once
// a shape (the fit dominates the test's time under the sanitizers).
struct Proxies {
  std::vector<glm::vec4> spheres;
  std::vector<mrgi::frame::OrientedPatch> patches;
  glm::dvec3 centre{0.0};
  double discs = 0.0, reach = 0.0, bound = 0.0;
};
Proxies fit_proxies(const Mesh& m) {
  Proxies f;
  f.spheres = mrgi::frame::fit_occluder_spheres(m.p, m.i);
  const std::vector<glm::vec3> albedo(m.i.size() / 3, glm::vec3(0.5f));
  f.patches = mrgi::frame::cluster_surface_orientations(m.p, m.i, albedo, MRGI_OBJECT_PATCHES);
  for (const glm::vec3& q : m.p) f.bound = std::max(f.bound, double(glm::length(q)));
  double volume = 0.0;
  for (const glm::vec4& s : f.spheres) {
    f.centre += glm::dvec3(glm::vec3(s)) * double(s.w * s.w * s.w);
    volume += double(s.w * s.w * s.w);
    f.discs += kPi * s.w * s.w;
  }
  f.centre /= volume;
  for (const glm::vec4& s : f.spheres) f.reach = std::max(f.reach, glm::distance(glm::dvec3(glm::vec3(s)), f.centre) + s.w);
  return f;
}

Ratios proxy_ratios(const Mesh& m, const Proxies& f, const glm::dvec3& from_dir, double distance_in_bounds) {
  const auto& spheres = f.spheres;
  const auto& patches = f.patches;
  const double bound = f.bound, discs = f.discs, reach = f.reach;
  const glm::dvec3 centre = f.centre;
  const glm::dvec3 o = glm::normalize(from_dir) * (distance_in_bounds * bound);
  const glm::dvec3 n = -glm::normalize(from_dir);
  const glm::vec3 w = glm::vec3(glm::normalize(centre - o));
  float silhouette = 0.0f;
  for (const auto& p : patches) silhouette += silhouette_area_term(glm::vec4(p.normal, p.facing_area), w);
  const float scale = far_field_scale(silhouette, float(discs), float(glm::length(centre - o) / reach));
  double open = 1.0;
  for (const glm::vec4& s : spheres) {
    const glm::dvec3 d = glm::dvec3(glm::vec3(s)) - o;
    const double l2 = glm::dot(d, d);
    open *= 1.0 - sphere_form_factor(float(glm::dot(n, d) / std::sqrt(l2)), float(s.w * s.w / l2));
  }
  const double exact = mesh_form_factor(m, o, n, bound);
  return {(1.0 - open) / exact, (1.0 - open) * scale / exact};
}

const glm::dvec3 kViews[] = {{1, 0, 0}, {0, 0, 1}, {0.6, 0.6, 0.5}, {-0.5, 0.7, -0.5}, {0.2, -0.9, 0.3}};

// Inscribed spheres overlap: seen from afar their caps lie over one another and, summed as
// independent occluders, hide about twice what a cube hides face-on. The far-field scale (the
// silhouette from the oriented patches over the spheres' disc area) brings them to the cube.
TEST(OcclusionFarField, ScaledProxiesHideWhatTheCubeHidesFarOff) {
  const Mesh cube = box(glm::vec3(-0.075f), glm::vec3(0.075f));
  const Proxies proxies = fit_proxies(cube);
  const Ratios face_on = proxy_ratios(cube, proxies, kViews[0], 12.0);
  EXPECT_GT(face_on.plain, 1.6);  // the over-count the scale is there for
  for (const glm::dvec3& v : kViews) {
    const Ratios r = proxy_ratios(cube, proxies, v, 12.0);
    EXPECT_NEAR(r.scaled, 1.0, 0.15) << "view " << v.x << " " << v.y << " " << v.z;
  }
}

// Near the object the spheres' own estimate holds (the scale fades out within 1.5 bounding
// radii). Over a cube, a 3:1:1 bar and a sphere, 5 views and 4 distances, the scaled proxies
// are nearer the mesh than the plain ones (mean |log ratio|), within 20 % of it at 8 bounding
// radii (eight patches stand in for a round silhouette, 15 % apart by direction; the bar's near
// end is nearer than its centre) and within [0.6, 1.75] everywhere, where the plain ones reach
// 4.1x (the bar end-on, its spheres stacked in depth).
TEST(OcclusionFarField, ScaledProxiesStayCloseToTheMeshAtEveryDistance) {
  const Mesh shapes[] = {box(glm::vec3(-0.075f), glm::vec3(0.075f)), box(glm::vec3(-0.3f, -0.1f, -0.1f), glm::vec3(0.3f, 0.1f, 0.1f)),
                         uv_sphere(0.2f)};
  double plain_log = 0.0, scaled_log = 0.0;
  int n = 0;
  for (size_t s = 0; s < 3; ++s) {
    const Proxies proxies = fit_proxies(shapes[s]);
    for (double distance : {1.6, 2.5, 4.0, 8.0})
      for (const glm::dvec3& v : kViews) {
        const Ratios r = proxy_ratios(shapes[s], proxies, v, distance);
        plain_log += std::abs(std::log(r.plain));
        scaled_log += std::abs(std::log(r.scaled));
        ++n;
        const std::string where = "shape " + std::to_string(s) + " at " + std::to_string(distance) + " view " +
                                  std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) +
                                  ": plain " + std::to_string(r.plain);
        EXPECT_GT(r.scaled, 0.6) << where;
        EXPECT_LT(r.scaled, 1.75) << where;
        if (distance >= 8.0) {
          EXPECT_NEAR(r.scaled, 1.0, 0.2) << where;
        }
      }
  }
  EXPECT_LT(scaled_log / n, 0.6 * plain_log / n) << "plain " << plain_log / n << ", scaled " << scaled_log / n;
}

TEST(OcclusionFarField, ScaleLimits) {
  EXPECT_FLOAT_EQ(far_field_scale(0.5f, 1.0f, 1.0f), 1.0f);   // within 1.5 radii: none
  EXPECT_FLOAT_EQ(far_field_scale(0.5f, 1.0f, 10.0f), 0.5f);  // beyond 4: the whole ratio
  EXPECT_FLOAT_EQ(far_field_scale(0.5f, 1.0f, 2.75f), 0.75f);
  EXPECT_FLOAT_EQ(far_field_scale(20.0f, 1.0f, 10.0f), 4.0f);  // at most 4 (a plate's thin proxies)
  EXPECT_FLOAT_EQ(far_field_scale(0.5f, 0.0f, 10.0f), 1.0f);   // nothing to scale by
  EXPECT_FLOAT_EQ(far_field_scale(0.0f, 1.0f, 10.0f), 1.0f);
}

// A radiance SH that is `l` in every direction (band 0 only).
mrgi::light::ShRgb uniform_sky(const glm::dvec3& l) {
  mrgi::light::ShRgb sh{};
  sh[0] = l * (2.0 * std::sqrt(kPi));  // Y00 = 1 / (2 sqrt(pi))
  return sh;
}

std::vector<mrgi::frame::OrientedPatch> unit_cube_patches(const glm::vec3& albedo) {
  std::vector<mrgi::frame::OrientedPatch> out;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      mrgi::frame::OrientedPatch p;
      p.normal = glm::vec3(0.0f);
      p.normal[axis] = sign;
      p.area = 1.0f;
      p.facing_area = 1.0f;
      p.albedo = albedo;
      out.push_back(p);
    }
  return out;
}

// Under a sky of radiance 1 everywhere the ground's albedo reads pi x 1 / pi = 1, held at 0.9.
// A black unit cube takes the light coming down on its top (pi) and on its four sides (pi / 2
// each): 3 pi, which the ground would have reflected at 0.9. A white one sends down as much
// as it takes (its sides half their light, its bottom all of the light from below): nothing.
TEST(OcclusionFarField, RealBounceFluxOfACubeUnderAUniformSky) {
  const auto sky = uniform_sky(glm::dvec3(1.0));
  const glm::vec3 centre(0.0f, 0.5f, 0.0f), base(0.0f);
  const auto black = unit_cube_patches(glm::vec3(0.0f));
  const glm::vec3 taken = mrgi::shading::real_bounce_flux(black.data(), 6, sky, {}, centre, base);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(taken[c], 0.9 * 3.0 * kPi, 0.03 * 0.9 * 3.0 * kPi);
  const auto white = unit_cube_patches(glm::vec3(1.0f));
  const glm::vec3 none = mrgi::shading::real_bounce_flux(white.data(), 6, sky, {}, centre, base);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(none[c], 0.0, 0.03 * 3.0 * kPi);
  // Radiance 0.6 + 0.4 y (1 straight up, 0.2 straight down; bands 0 and 1): a darker ground
  // (pi x 0.4 / (0.6 pi + 0.4 x 2 pi / 3) = 0.46) under less light, a smaller loss.
  mrgi::light::ShRgb grey{};
  grey[0] = glm::dvec3(0.6 * 2.0 * std::sqrt(kPi));
  grey[1] = glm::dvec3(-0.4 / 0.488602511902920);  // Y1-1 = -0.4886 y
  const glm::vec3 grey_taken = mrgi::shading::real_bounce_flux(black.data(), 6, grey, {}, centre, base);
  EXPECT_GT(grey_taken.x, 0.0f);
  EXPECT_LT(grey_taken.x, 0.5f * taken.x);
}

// A lamp straight above adds its light on the top to what the ground loses; a black sky (no
// light from below: the ground's albedo unknown) makes the loss nothing.
TEST(OcclusionFarField, RealBounceFluxTakesTheLampsShareAndNeedsTheGroundsAlbedo) {
  mrgi::LightDesc sun;
  sun.type = mrgi::LightType::Directional;
  sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  sun.intensity = 10.0f;
  const auto black = unit_cube_patches(glm::vec3(0.0f));
  const glm::vec3 centre(0.0f, 0.5f, 0.0f), base(0.0f);
  const auto sky = uniform_sky(glm::dvec3(1.0));
  const glm::vec3 sky_only = mrgi::shading::real_bounce_flux(black.data(), 6, sky, {}, centre, base);
  const glm::vec3 with_sun = mrgi::shading::real_bounce_flux(black.data(), 6, sky, {sun}, centre, base);
  // The ground's albedo: pi x 1 / (pi + 10), the top's extra 10 W.
  const double albedo = kPi / (kPi + 10.0);
  EXPECT_NEAR(with_sun.x, albedo * (3.0 * kPi + 10.0), 0.03 * albedo * (3.0 * kPi + 10.0));
  EXPECT_LT(with_sun.x, sky_only.x);  // a brighter ground for the same sky reads darker
  const glm::vec3 dark = mrgi::shading::real_bounce_flux(black.data(), 6, mrgi::light::ShRgb{}, {sun}, centre, base);
  EXPECT_FLOAT_EQ(dark.x, 0.0f);
}

// The loss reaches a wall facing the object's base as from a diffuse emitter on the ground;
// nothing on the ground itself (grazing) or below it; softened near the base.
TEST(OcclusionFarField, RealBounceLossFallsOffAsADiffuseEmitterOnTheGround) {
  const glm::vec3 flux(1.0f), base(0.0f);
  // A wall 1 m away along -x facing +x, at 1 m height: cos at the emitter and at the wall 1 / sqrt 2.
  const glm::vec3 p(-1.0f, 1.0f, 0.0f), n(1.0f, 0.0f, 0.0f);
  const float soft = 0.1f;
  EXPECT_NEAR(real_bounce_loss(flux, base, soft, p, n).x, 0.5 / (kPi * (2.0 + soft * soft)), 1e-6);
  EXPECT_FLOAT_EQ(real_bounce_loss(flux, base, soft, glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0, 1, 0)).x, 0.0f);
  EXPECT_FLOAT_EQ(real_bounce_loss(flux, base, soft, glm::vec3(0.0f, -1.0f, 0.0f), glm::vec3(0, 1, 0)).x, 0.0f);
  // Facing away: nothing.
  EXPECT_FLOAT_EQ(real_bounce_loss(flux, base, soft, p, -n).x, 0.0f);
  // At the base, finite.
  EXPECT_TRUE(std::isfinite(real_bounce_loss(flux, base, soft, glm::vec3(0.0f, 1e-6f, 0.0f), glm::vec3(0, -1, 0)).x));
}

}  // namespace
