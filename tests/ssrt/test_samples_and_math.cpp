// The ssrt sample sets (spherical Delaunay, chi of eq. 9, pre-computed SH weights) and the
// per-sample shader math of shaders/shared/transfer_math.h (eq. 6-8, 10-15), checked on the CPU.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "../../shaders/shared/transfer_math.h"
#include "technique/ssrt/sample_directions.h"
#include "light/sh_tools.h"

namespace {
using namespace mrgi;
using namespace mrgi::ssrt;
using mrgi::shader::vec3;

constexpr double kPi = 3.14159265358979323846;

TEST(SsrtSamples, OctahedronTriangulation) {
  const std::vector<glm::dvec3> p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  auto tris = spherical_delaunay(p);
  ASSERT_TRUE(tris.ok()) << tris.error().message;
  EXPECT_EQ(tris->size(), 8u);
  EXPECT_NEAR(median_edge_angle(p, *tris), kPi / 2.0, 1e-12);
}

TEST(SsrtSamples, DelaunayOfRandomPointsIsAClosedEmptyCircleTriangulation) {
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<glm::dvec3> p(200);
  for (auto& v : p) v = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
  auto tris = spherical_delaunay(p);
  ASSERT_TRUE(tris.ok());
  // Euler for a triangulated sphere: F = 2V - 4, E = 3V - 6.
  EXPECT_EQ(tris->size(), 2 * p.size() - 4);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& t : *tris) {
    for (int e = 0; e < 3; ++e)
      edges.insert({std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])});
    // Empty circumcircle on the sphere = no point above the triangle's plane.
    const glm::dvec3 n = glm::cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]);
    for (const auto& q : p) EXPECT_LE(glm::dot(n, q - p[t[0]]), 1e-9);
  }
  EXPECT_EQ(edges.size(), 3 * p.size() - 6);
}

TEST(SsrtSamples, CoplanarOrTooFewPointsAreRefused) {
  EXPECT_FALSE(spherical_delaunay({{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}}).ok());
  auto flat = spherical_delaunay({{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}});
  ASSERT_FALSE(flat.ok());
  EXPECT_EQ(flat.error().kind, ErrorKind::BadInput);
}

TEST(SsrtSamples, SetsCoverTheSphereAndChiFollowsTheDensity) {
  for (uint32_t n : {16u, 64u, 256u}) {
    auto s = make_sample_sets({n, 1});
    ASSERT_TRUE(s.ok());
    ASSERT_EQ(s->samples.size(), size_t(kJitterSets) * n);
    // A triangular lattice of n points: spacing sqrt(8 pi / (sqrt(3) n)).
    const double lattice = std::sqrt(8.0 * kPi / (std::sqrt(3.0) * n));
    EXPECT_NEAR(s->median_neighbour_angle, lattice, 0.3 * lattice) << n;
    EXPECT_NEAR(s->chi, 1.0 - std::cos(0.5 * s->median_neighbour_angle), 1e-6);
    for (int set = 0; set < kJitterSets; ++set) {
      // The SH weights integrate the basis: sum_j Y_i(w_j) dw ~ integral Y_i = sqrt(4 pi) d_i0.
      double sums[16] = {};
      for (uint32_t j = 0; j < n; ++j) {
        const GpuSample& g = s->samples[size_t(set) * n + j];
        EXPECT_NEAR(glm::length(glm::vec3(g.direction_and_radius)), 1.0f, 1e-5f);
        EXPECT_GT(g.direction_and_radius.w, 0.0f);
        EXPECT_LE(g.direction_and_radius.w, 1.0f);
        for (int i = 0; i < 16; ++i) sums[i] += g.sh_weights[i / 4][i % 4];
      }
      EXPECT_NEAR(sums[0], std::sqrt(4.0 * kPi), 1e-4);
      // Odd bands integrate to 0 exactly (antipodal pairs); even ones up to the jitter.
      for (int i = 1; i < 4; ++i) EXPECT_NEAR(sums[i], 0.0, 1e-5) << "band 1, N " << n;
      for (int i = 9; i < 16; ++i) EXPECT_NEAR(sums[i], 0.0, 1e-5) << "band 3, N " << n;
      // (16 directions are too coarse for band 2 to integrate well; the ladder uses >= 32.)
      // Jittered random sampling: the error shrinks like 1/sqrt(N).
      if (n >= 64) {
        for (int i = 4; i < 9; ++i)
          EXPECT_NEAR(sums[i], 0.0, 3.0 / std::sqrt(double(n))) << "band 2, N " << n;
      }
    }
  }
  auto a = make_sample_sets({32, 5});
  auto b = make_sample_sets({32, 5});
  auto c = make_sample_sets({32, 6});
  EXPECT_EQ(a->samples[17].direction_and_radius, b->samples[17].direction_and_radius);
  EXPECT_NE(a->samples[17].direction_and_radius, c->samples[17].direction_and_radius);
  EXPECT_FALSE(make_sample_sets({4, 1}).ok());
  EXPECT_FALSE(make_sample_sets({2000, 1}).ok());
  EXPECT_FALSE(make_sample_sets({33, 1}).ok());
}

TEST(SsrtMath, ContinuousVisibilityRisesOverHalfASampleSpacing) {
  const float median = 0.4f;
  const float chi = shader::ssrt_chi_from_median_angle(median);
  const vec3 x(0.0f), w(0.0f, 0.0f, 1.0f);
  // Occluder straight along w: blocked.
  EXPECT_FLOAT_EQ(shader::ssrt_visibility_k(x, vec3(0, 0, 2), w, chi), 0.0f);
  // At half the median angle K reaches 1; beyond it stays 1; in between it rises monotonically.
  auto at = [&](float angle) {
    return shader::ssrt_visibility_k(x, vec3(std::sin(angle), 0, std::cos(angle)), w, chi);
  };
  EXPECT_NEAR(at(0.5f * median), 1.0f, 1e-4f);
  EXPECT_FLOAT_EQ(at(1.5f), 1.0f);
  float last = 0.0f;
  for (float a = 0.0f; a <= 0.5f * median; a += 0.01f) {
    EXPECT_GE(at(a), last);
    last = at(a);
  }
  EXPECT_NEAR(at(0.25f * median), (1.0f - std::cos(0.25f * median)) / chi, 1e-4f);
  // Degenerate s == x: visible, never NaN.
  EXPECT_EQ(shader::ssrt_visibility_k(x, x, w, chi), 1.0f);
}

TEST(SsrtMath, TransferOfAnUnoccludedPixelGivesTheLambertianRadiance) {
  auto s = make_sample_sets({256, 3});
  ASSERT_TRUE(s.ok());
  // Uniform radiance L: a white Lambertian surface reflects L. dot(T, l) with l_0 = L sqrt(4pi).
  const float L = 2.0f;
  const vec3 n = glm::normalize(vec3(0.3f, -0.5f, 0.8f));
  for (int set = 0; set < kJitterSets; ++set) {
    double t0 = 0.0;
    for (uint32_t j = 0; j < s->directions; ++j) {
      const GpuSample& g = s->samples[size_t(set) * s->directions + j];
      t0 += shader::ssrt_transfer_weight(n, vec3(g.direction_and_radius), 1.0f, 1.0f) *
            g.sh_weights[0].x;
    }
    EXPECT_NEAR(t0 * L * std::sqrt(4.0 * kPi), L, 0.05 * L) << "set " << set;
  }
}

TEST(SsrtMath, FormFactorAndFacingGate) {
  const vec3 x(0.0f), nx(0, 0, 1), s(0, 0, 1), ns(0, 0, -1);
  const float area = 0.01f;
  EXPECT_NEAR(shader::ssrt_form_factor(x, nx, s, ns, area, 0.01f), area / float(kPi), 1e-7f);
  // Twice the distance: a quarter.
  EXPECT_NEAR(shader::ssrt_form_factor(x, nx, vec3(0, 0, 2), ns, area, 0.01f),
              area / float(kPi) / 4.0f, 1e-7f);
  // Sender facing away or receiver behind: nothing.
  EXPECT_EQ(shader::ssrt_form_factor(x, nx, s, vec3(0, 0, 1), area, 0.01f), 0.0f);
  EXPECT_EQ(shader::ssrt_form_factor(x, nx, vec3(0, 0, -1), vec3(0, 0, 1), area, 0.01f), 0.0f);
  EXPECT_EQ(shader::ssrt_facing_gate(ns, vec3(0, 0, 1)), 1.0f);
  EXPECT_EQ(shader::ssrt_facing_gate(vec3(0, 0, 1), vec3(0, 0, 1)), 0.0f);
  // The distance clamp bounds the 1/d^2 singularity.
  const float near = shader::ssrt_form_factor(x, nx, vec3(0, 0, 1e-6f), ns, 1.0f, 0.05f);
  EXPECT_TRUE(std::isfinite(near));
  EXPECT_LE(near, 1.0f);
}

TEST(SsrtMath, IndirectTermOnlyFromOccludingLitSenders) {
  const vec3 x(0.0f), nx(0, 0, 1), s(0, 0, 0.5f), ns(0, 0, -1), albedo(0.8f, 0.2f, 0.1f);
  const vec3 light_dir(0, 0, -1), e(3.0f);
  const vec3 full = shader::ssrt_indirect_term(x, nx, s, ns, albedo, 0.0f, light_dir, e, 0.01f, 0.01f);
  // Expected: albedo * E * cos / pi (sender radiance) * pi * F.
  const float f = shader::ssrt_form_factor(x, nx, s, ns, 0.01f, 0.01f);
  EXPECT_NEAR(full.x, 0.8f * 3.0f / float(kPi) * float(kPi) * f, 1e-6f);
  EXPECT_GT(full.x, full.y);  // coloured by the sender's albedo
  // Visible sample (K = 1): no bounce. Sender not lit: no bounce.
  EXPECT_EQ(shader::ssrt_indirect_term(x, nx, s, ns, albedo, 1.0f, light_dir, e, 0.01f, 0.01f).x, 0.0f);
  EXPECT_EQ(shader::ssrt_indirect_term(x, nx, s, ns, albedo, 0.0f, -light_dir, e, 0.01f, 0.01f).x, 0.0f);
}

TEST(SsrtMath, ToneMapAndDifferentialComposite) {
  // Reinhard: L = avg maps to key / (1 + key) when white is large; monotonic; bounded.
  EXPECT_NEAR(shader::ssrt_reinhard(2.0f, 0.18f, 2.0f, 1e6f), 0.18f / 1.18f, 1e-6f);
  EXPECT_EQ(shader::ssrt_reinhard(1.0f, 0.18f, 0.0f, 1.0f), 0.0f);
  EXPECT_NEAR(shader::ssrt_reinhard(1e30f, 0.18f, 1e-30f, 1e6f), 1.0f, 1e-6f);  // HDR: white
  EXPECT_NEAR(shader::ssrt_reinhard(4.0f, 1.0f, 1.0f, 4.0f), 1.0f, 1e-6f);  // L_white -> 1
  EXPECT_LT(shader::ssrt_reinhard(1.0f, 0.18f, 1.0f, 1e6f),
            shader::ssrt_reinhard(2.0f, 0.18f, 1.0f, 1e6f));
  const vec3 cam(0.5f, 0.4f, 0.3f);
  // No change where the virtual object has no effect: exactly the camera.
  const vec3 same = shader::ssrt_direct_differential(cam, 1.3f, 1.3f, 0.18f, 1.0f, 1e6f);
  EXPECT_EQ(same.x, cam.x);
  EXPECT_EQ(same.z, cam.z);
  // A shadow darkens, more light brightens, never negative.
  EXPECT_LT(shader::ssrt_direct_differential(cam, 1.0f, 0.2f, 0.18f, 1.0f, 1e6f).x, cam.x);
  EXPECT_GT(shader::ssrt_direct_differential(cam, 1.0f, 2.0f, 0.18f, 1.0f, 1e6f).x, cam.x);
  EXPECT_GE(shader::ssrt_direct_differential(cam, 1e6f, 0.0f, 50.0f, 1e-6f, 1e6f).x, 0.0f);
  // Eq. 14: equal bounce buffers select nothing, different ones select R'_i.
  EXPECT_EQ(shader::ssrt_indirect_select(vec3(0.3f), vec3(0.3f), 1e-3f).x, 0.0f);
  EXPECT_EQ(shader::ssrt_indirect_select(vec3(0.3f), vec3(0.5f), 1e-3f).x, 0.5f);
  const vec3 out = shader::ssrt_compose_real(cam, 1.0f, 1.0f, vec3(0.1f), vec3(0.4f),
                                             vec3(0.5f), 0.18f, 1.0f, 1e6f, 1e-3f);
  EXPECT_NEAR(out.x, cam.x + 0.4f * 0.5f / float(kPi), 1e-6f);
}

}  // namespace

namespace {

// The transfer loops over the N/2 antipodal pairs of a set and takes the member facing the
// receiver, with the SH basis evaluated in the shader (transfer.comp); that must be the sum over
// all N samples with the buffer's pre-computed weights, where back-facing samples contribute 0.
TEST(SsrtSamples, PairLoopEqualsTheSumOverAllSamples) {
  for (uint32_t n : {16u, 32u, 64u}) {
    auto s = make_sample_sets({n, 20140901});
    ASSERT_TRUE(s.ok());
    std::mt19937 rng(n);
    std::normal_distribution<float> g(0.0f, 1.0f);
    const float solid_angle = 4.0f * float(kPi) / float(n);
    for (int trial = 0; trial < 20; ++trial) {
      const vec3 normal = glm::normalize(vec3(g(rng), g(rng), g(rng)));
      for (int set = 0; set < kJitterSets; ++set) {
        const GpuSample* base = &s->samples[size_t(set) * n];
        double all[16] = {}, pairs[16] = {};
        double radius_all = 0.0, radius_pairs = 0.0;
        for (uint32_t j = 0; j < n; ++j) {
          const vec3 w(base[j].direction_and_radius);
          if (!(glm::dot(normal, w) > 0.0f)) continue;
          const float tw = shader::ssrt_transfer_weight(normal, w, 1.0f, 1.0f);
          for (int c = 0; c < 16; ++c) all[c] += tw * base[j].sh_weights[c / 4][c % 4];
          radius_all += base[j].direction_and_radius.w;
        }
        for (uint32_t j = 0; j < n / 2; ++j) {
          const vec3 w0(base[j].direction_and_radius);
          const bool flip = glm::dot(normal, w0) < 0.0f;
          const vec3 w = flip ? -w0 : w0;
          // The antipode really is the other member of the pair.
          ASSERT_LT(glm::length(vec3(base[j + n / 2].direction_and_radius) + w0), 1e-6f);
          if (!(glm::dot(normal, w) > 0.0f)) continue;
          const float tw = shader::ssrt_transfer_weight(normal, w, 1.0f, 1.0f);
          const shader::SH16 y = shader::sh_basis16(w);
          for (int c = 0; c < 16; ++c) pairs[c] += tw * shader::sh_get(y, c) * solid_angle;
          radius_pairs += (flip ? base[j + n / 2] : base[j]).direction_and_radius.w;
        }
        for (int c = 0; c < 16; ++c) EXPECT_NEAR(pairs[c], all[c], 1e-5) << "n " << n << " c " << c;
        EXPECT_NEAR(radius_pairs, radius_all, 1e-5);
      }
    }
  }
}

// tangent_plane_depth: a coarse G-buffer texel's tangent plane met by another pixel's ray.
TEST(SsrtMath, PlaneDepthIsExactOnAPlaneAndFallsBackWhereItCannotBe) {
  // Plane z = 2 + 0.5 x (camera space), texel centre at x = 0.
  const vec3 n = glm::normalize(vec3(-0.5f, 0.0f, 1.0f));
  const vec3 p(0.0f, 0.0f, 2.0f);
  for (float u : {-0.02f, -0.01f, 0.0f, 0.01f, 0.02f}) {
    const vec3 ray(u, 0.0f, 1.0f);  // z = 1
    const float z = shader::tangent_plane_depth(ray, p, n, 0.05f);
    // On the plane: z = 2 + 0.5 (u z)  =>  z = 2 / (1 - 0.5 u).
    EXPECT_NEAR(z, 2.0f / (1.0f - 0.5f * u), 1e-5f) << u;
  }
  // Farther than 5 % from the texel's depth: a depth edge, not the plane.
  EXPECT_FLOAT_EQ(shader::tangent_plane_depth(vec3(0.3f, 0.0f, 1.0f), p, n, 0.05f), 2.0f);
  // A ray grazing the plane, a plane through the camera: the texel's depth, never NaN or inf.
  const vec3 side = glm::normalize(vec3(1.0f, 0.0f, 0.0f));
  EXPECT_FLOAT_EQ(shader::tangent_plane_depth(vec3(0.0f, 0.0f, 1.0f), p, side, 0.05f), 2.0f);
  EXPECT_FLOAT_EQ(shader::tangent_plane_depth(vec3(0.0f, 0.0f, 1.0f), vec3(0.0f), n, 0.05f), 0.0f);
}

}  // namespace

namespace {
using mrgi::shader::vec4;

// shade_tiles.comp skips a tile when ssrt_tile_invisible says shading it moves no pixel by a
// visible amount. Random footprints of 4 x 4 real cells that it accepts are interpolated as
// shade.comp does (Catmull-Rom, weights summing to 1, clamped at 0), shaded (L_r = A R_d,
// L_rv = A (R'_d + eq. 14's select / pi)) and composed (mrgi_shared.h compose_encoded, random
// camera values and exposures): the 8-bit result is never more than one level from the camera's
// own, which the skipped tile keeps. The rule must also accept some footprints, or it saves
// nothing.
TEST(SsrtMath, SkippedTilesAreWithinOneLevelOfShadingThem) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float tolerance = 1.0f / 128.0f, eps = 1e-3f, alpha_max = 10.0f;
  int accepted = 0, checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const float base = 0.02f + 3.0f * u(rng), spread = base * 0.6f * u(rng);
    const float scale_d = std::pow(10.0f, -4.0f + 3.5f * u(rng));  // |R'_d - R_d| / R_d scale
    const bool bounce = u(rng) < 0.5f;
    float rd[16], rdv[16];
    vec3 ri[16], riv[16];
    float d_max = 0.0f, i_max = 0.0f, lo = 1e30f, hi = 0.0f;
    for (int k = 0; k < 16; ++k) {
      rd[k] = base + spread * u(rng);
      rdv[k] = std::max(0.0f, rd[k] * (1.0f + scale_d * (2.0f * u(rng) - 1.0f)));
      ri[k] = vec3(0.05f * u(rng), 0.05f * u(rng), 0.05f * u(rng));
      riv[k] = bounce ? ri[k] + vec3(scale_d * base * u(rng)) : ri[k];
      d_max = std::max(d_max, std::abs(rdv[k] - rd[k]));
      if (bounce) i_max = std::max({i_max, riv[k].x, riv[k].y, riv[k].z});
      lo = std::min(lo, rd[k]);
      hi = std::max(hi, rd[k]);
    }
    if (!shader::ssrt_tile_invisible(d_max, i_max, lo, hi, tolerance)) continue;
    ++accepted;
    for (int pixel = 0; pixel < 8; ++pixel) {
      const vec4 wx = shader::ssrt_catmull_rom(u(rng)), wy = shader::ssrt_catmull_rom(u(rng));
      float s_rd = 0.0f, s_rdv = 0.0f;
      vec3 s_ri(0.0f), s_riv(0.0f);
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const float w = wx[i] * wy[j];
          s_rd += w * rd[j * 4 + i];
          s_rdv += w * rdv[j * 4 + i];
          s_ri += w * ri[j * 4 + i];
          s_riv += w * riv[j * 4 + i];
        }
      s_rd = std::max(s_rd, 0.0f);
      s_rdv = std::max(s_rdv, 0.0f);
      s_ri = glm::max(s_ri, vec3(0.0f));
      s_riv = glm::max(s_riv, vec3(0.0f));
      const float exposure = 0.5f + 1.5f * u(rng);
      const vec3 camera(u(rng), u(rng), u(rng));
      const vec3 a = glm::clamp(camera / exposure, vec3(0.0f), vec3(1.0f));
      const vec3 l_r = a * s_rd;
      const vec3 l_rv = a * s_rdv + a * shader::ssrt_indirect_select(s_ri, s_riv, 1e-3f) / float(kPi);
      const vec3 out = shader::compose_encoded(camera, l_r, l_rv, 0.0f, exposure, eps, alpha_max);
      for (int c = 0; c < 3; ++c) {
        const int shaded = int(std::lround(out[c] * 255.0f));
        const int kept = int(std::lround(shader::srgb_encode1(camera[c]) * 255.0f));
        ASSERT_LE(std::abs(shaded - kept), 1) << "trial " << trial << " channel " << c;
        ++checked;
      }
    }
  }
  EXPECT_GT(accepted, 1000) << "the rule should accept footprints whose solutions barely differ";
  EXPECT_GT(checked, 0);
  // And refuse: no light (R_d = 0), a difference above the tolerance.
  EXPECT_FALSE(shader::ssrt_tile_invisible(0.0f, 0.0f, 0.0f, 1.0f, tolerance));
  EXPECT_FALSE(shader::ssrt_tile_invisible(0.02f, 0.0f, 1.0f, 1.0f, tolerance));
  EXPECT_TRUE(shader::ssrt_tile_invisible(0.002f, 0.0f, 1.0f, 1.0f, tolerance));
}

}  // namespace
