// Light estimation of the ssrt technique (paper Sec. 5.2): recovery of known SH lights from
// synthetic transfer vectors built the way the GPU builds them (sample sets with pre-computed SH
// weights, continuous visibility), and the regularised solve on singular and extreme systems.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "../../shaders/shared/transfer_math.h"
#include "common/sh_sky.h"
#include "light/sh_estimator.h"
#include "technique/ssrt/sample_directions.h"

namespace {
using namespace mrgi;
using namespace mrgi::ssrt;
using namespace mrgi::light;

constexpr double kPi = 3.14159265358979323846;

// The transfer vector of a pixel with normal n whose sample directions inside `blocked_cone`
// (unit axis, cosine) are occluded: T_i = sum_j K_j max(n.w_j, 0) dw / pi * Y_i(w_j).
ShVector transfer_vector(const SampleSets& sets, int set, const glm::vec3& n,
                         const glm::vec3& block_axis, float block_cos) {
  ShVector t{};
  for (uint32_t j = 0; j < sets.directions; ++j) {
    const GpuSample& s = sets.samples[size_t(set) * sets.directions + j];
    const glm::vec3 w(s.direction_and_radius);
    const float k = glm::dot(w, block_axis) > block_cos ? 0.0f : 1.0f;
    // sh_weights already hold Y_i * dw; transfer weight without the solid angle:
    const float weight = mrgi::shader::ssrt_transfer_weight(n, w, k, 1.0f);
    for (int i = 0; i < 16; ++i) t[i] += weight * s.sh_weights[i / 4][i % 4];
  }
  return t;
}

glm::vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  glm::vec3 v(g(rng), g(rng), g(rng));
  return glm::normalize(v);
}

double dot_rgb(const ShVector& t, const ShRgb& l, int c) {
  double s = 0.0;
  for (int i = 0; i < 16; ++i) s += double(t[i]) * l[i][c];
  return s;
}

// A frame of `pixels` with random normals and random occluding cones, lit by `light`.
LightSystem synthetic_frame(const SampleSets& sets, const ShRgb& light, double albedo,
                            int pixels, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  LightSystem sys;
  for (int p = 0; p < pixels; ++p) {
    const glm::vec3 n = random_unit(rng);
    const glm::vec3 axis = glm::normalize(n + random_unit(rng));
    const float cone = 0.3f + 0.7f * u(rng);
    const ShVector t = transfer_vector(sets, p % kJitterSets, n, axis, cone);
    sys.add(t, albedo * glm::dvec3(dot_rgb(t, light, 0), dot_rgb(t, light, 1),
                                   dot_rgb(t, light, 2)));
  }
  return sys;
}

SampleSets samples(uint32_t n = 64) {
  auto s = make_sample_sets({n, 7});
  EXPECT_TRUE(s.ok());
  return *s;
}

TEST(SsrtLightEstimation, RecoversKnownLightFromSyntheticTransfer) {
  const SampleSets sets = samples();
  ShRgb light{};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  light[0] = glm::dvec3(2.0, 1.5, 1.0);
  for (int i = 1; i < 16; ++i) light[i] = glm::dvec3(u(rng), u(rng), u(rng));
  LightEstimatorSettings s;
  s.white_light = false;
  s.relative_regularisation = 1e-9;
  s.below_surface_penalty = 0.0;  // plain least squares: the light here comes from everywhere
  s.gray_albedo = 0.5;
  auto est = LightEstimator::create(s);
  ASSERT_TRUE(est.ok()) << est.error().message;
  const LightSystem sys = synthetic_frame(sets, light, 0.5, 4000, 11);
  ASSERT_TRUE(est->update(sys, 0, 0.0).ok());
  for (int i = 0; i < 16; ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(est->frame_solution()[i][c], light[i][c], 1e-3) << "coefficient " << i;
  EXPECT_FLOAT_EQ(est->estimate().confidence, 1.0f);
  EXPECT_TRUE(est->estimate().valid);
}

TEST(SsrtLightEstimation, DefaultRegularisationKeepsIrradianceClose) {
  const SampleSets sets = samples();
  const ShRgb light = sh_directional_light(glm::normalize(glm::dvec3(0.3, 1.0, 0.2)),
                                           glm::dvec3(3.0));
  ShRgb lit = light;
  lit[0] += glm::dvec3(0.4 * std::sqrt(4.0 * kPi));  // plus a uniform ambient of 0.4
  auto est = LightEstimator::create({});
  ASSERT_TRUE(est.ok());
  ASSERT_TRUE(est->update(synthetic_frame(sets, lit, 0.5, 3000, 5), 0, 0.0).ok());
  std::mt19937 rng(9);
  for (int k = 0; k < 50; ++k) {
    const glm::vec3 n = random_unit(rng);
    const double truth = sh_irradiance(lit, n).y;
    const double got = sh_irradiance(est->filtered(), n).y;
    // The default Tikhonov weight (1e-2, chosen against sampling noise) costs a few per cent.
    EXPECT_NEAR(got, truth, 0.08 * (1.0 + truth)) << "normal " << k;
  }
}

TEST(SsrtLightEstimation, DominantDirectionAndIntensityOfADirectionalLight) {
  const SampleSets sets = samples();
  const glm::dvec3 dir = glm::normalize(glm::dvec3(-0.5, 0.8, 0.3));
  ShRgb lit = sh_directional_light(dir, glm::dvec3(5.0));
  lit[0] += glm::dvec3(0.2 * std::sqrt(4.0 * kPi));
  LightEstimatorSettings s;
  s.relative_regularisation = 1e-9;
  s.below_surface_penalty = 0.0;  // normals from every side: no surface dominates
  auto est = LightEstimator::create(s);
  ASSERT_TRUE(est.ok());
  auto r = est->update(synthetic_frame(sets, lit, 0.5, 3000, 21), 0, 0.0);
  ASSERT_TRUE(r.ok());
  const glm::dvec3 got(r->direction_to_light[0], r->direction_to_light[1],
                       r->direction_to_light[2]);
  const double angle_deg = std::acos(std::clamp(glm::dot(got, dir), -1.0, 1.0)) * 180.0 / kPi;
  EXPECT_LT(angle_deg, 1.0);
  // Intensity from bands 1-2 only, so the ambient in band 0 does not leak into it.
  EXPECT_NEAR(r->dominant_intensity[1], 5.0, 0.05);
  // Exported irradiance SH agrees with the directly computed one.
  const auto e = irradiance_at(*r, {0.0f, 1.0f, 0.0f});
  EXPECT_NEAR(e[1], sh_irradiance(est->filtered(), glm::vec3(0, 1, 0)).y, 1e-3);
}

TEST(SsrtLightEstimation, OneFlatWallStaysFiniteBoundedAndReproducesTheWall) {
  const SampleSets sets = samples();
  const ShRgb lit = sh_directional_light(glm::dvec3(0, 0, 1), glm::dvec3(2.0));
  const ShVector t = transfer_vector(sets, 0, glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), 2.0f);
  LightSystem sys;
  const double wall = 0.5 * dot_rgb(t, lit, 1);
  for (int p = 0; p < 10000; ++p) sys.add(t, glm::dvec3(wall));
  for (double rel : {1e-3, 0.0}) {  // 0: only the absolute floor keeps it solvable
    LightEstimatorSettings s;
    s.relative_regularisation = rel;
    auto est = LightEstimator::create(s);
    ASSERT_TRUE(est.ok());
    auto r = est->update(sys, 0, 0.0);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_TRUE(is_finite(est->filtered()));
    for (int i = 0; i < 16; ++i) EXPECT_LT(std::abs(est->filtered()[i].y), 20.0) << i;
    // The wall's own pixels are reproduced (the data direction is fully constrained).
    EXPECT_NEAR(0.5 * dot_rgb(t, est->filtered(), 1), wall, 0.02 * wall);
    EXPECT_LE(r->confidence, 2.0f / 16.0f);
  }
}

// A frame of nothing but an open floor (normal up) that is darker than the prior predicts: the
// data cannot tell ambient from an overhead light, so the estimate must lower the ambient, not
// point the light downwards (what plain Tikhonov towards the prior did). With the ambient
// re-fit off, the old behaviour comes back, so the test can fail.
TEST(SsrtLightEstimation, DarkFloorLowersTheAmbientInsteadOfLightingFromBelow) {
  const SampleSets sets = samples();
  const ShVector t = transfer_vector(sets, 0, glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), 2.0f);
  LightSystem sys;
  const double floor = 0.1;  // camera intensity; the prior (0.5 uniform) predicts 0.25
  for (int p = 0; p < 5000; ++p) sys.add(t, glm::dvec3(floor));
  for (bool refit : {true, false}) {
    LightEstimatorSettings s;
    s.refit_prior_ambient = refit;
    s.below_surface_penalty = 0.0;  // the prior of the next test would also keep it up
    auto est = LightEstimator::create(s);
    ASSERT_TRUE(est.ok());
    auto r = est->update(sys, 0, 0.0);
    ASSERT_TRUE(r.ok());
    // The floor is reproduced either way (the data direction is constrained).
    EXPECT_NEAR(0.5 * dot_rgb(t, est->filtered(), 1), floor, 0.05 * floor);
    // Band 1's "up" part (index 2 holds z; index 1 holds -y under the Condon-Shortley phase).
    const double up = -est->filtered()[1].y;
    if (refit) {
      EXPECT_GE(up, -0.02 * est->filtered()[0].y) << "the light must not come from below";
    } else {
      EXPECT_LT(up, -0.05 * est->filtered()[0].y) << "plain Tikhonov points it down";
    }
  }
}

// What a camera sees of a tabletop: mostly floor, and only faces turned towards it (normals
// with y >= 0 and z <= 0), some with occluding cones; lit by a sun at 34 degrees elevation
// behind the camera and a sky, with nothing from below the floor (as in the suite's
// env_fisheye). Light from behind the camera's view and from below is unconstrained; plain
// Tikhonov spreads light there and the dominant direction sinks towards the horizon. The
// below-surface prior finds the floor as the dominant surface and keeps that hemisphere dark.
TEST(SsrtLightEstimation, DarkHemisphereBehindTheDominantSurfaceKeepsTheDirection) {
  const SampleSets sets = samples();
  const glm::dvec3 sun = glm::normalize(glm::dvec3(-0.16, 0.55, -0.82));
  ShRgb lit = sh_directional_light(sun, glm::dvec3(3.0));
  test::add_sh_sky(lit, 0.4);
  glm::dvec3 truth(0.0);
  ASSERT_TRUE(sh_dominant_direction(lit, truth));
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  LightSystem sys;
  for (int p = 0; p < 4000; ++p) {
    glm::vec3 n(0.0f, 1.0f, 0.0f);
    glm::vec3 axis(1.0f, 0.0f, 0.0f);
    float cone = 2.0f;  // nothing blocked
    if (p % 50 < 2) {  // 4 % object faces turned towards the camera, partly occluded
      n = random_unit(rng);
      n = glm::normalize(glm::vec3(n.x, std::abs(n.y), -std::abs(n.z)));
      axis = glm::normalize(n + random_unit(rng));
      cone = 0.3f + 0.7f * u(rng);
    }
    const ShVector t = transfer_vector(sets, p % kJitterSets, n, axis, cone);
    // The objects are brighter than the grey world's 0.5 (as env_fisheye's boxes and ball are),
    // the error the unconstrained directions then absorb.
    const double albedo = p % 50 < 2 ? 0.65 : 0.5;
    sys.add(t, albedo * glm::dvec3(dot_rgb(t, lit, 0), dot_rgb(t, lit, 1), dot_rgb(t, lit, 2)));
  }
  auto angle_deg = [&](double mu, glm::dvec3* normal) {
    LightEstimatorSettings s;
    s.below_surface_penalty = mu;
    auto est = LightEstimator::create(s);
    EXPECT_TRUE(est.ok());
    auto r = est->update(sys, 0, 0.0);
    EXPECT_TRUE(r.ok());
    if (normal) *normal = est->dominant_normal();
    const glm::dvec3 got(r->direction_to_light[0], r->direction_to_light[1],
                         r->direction_to_light[2]);
    return std::acos(std::clamp(glm::dot(got, truth), -1.0, 1.0)) * 180.0 / kPi;
  };
  glm::dvec3 normal(0.0);
  const double with_prior = angle_deg(LightEstimatorSettings{}.below_surface_penalty, &normal);
  const double without = angle_deg(0.0, nullptr);
  EXPECT_GT(normal.y, 0.99) << "the floor is the dominant surface";
  // Seeded, so exact: 15.1 degrees with the prior, 27.9 without (the real capture's effect is
  // larger, 68 -> 9 degrees: SsrtReplay.EnvFisheyeLightDirectionAndRdeBeatBaseline).
  EXPECT_LT(with_prior, 18.0);
  EXPECT_GT(without, 25.0) << "without the prior the direction sinks (so the test can fail)";
}

TEST(SsrtLightEstimation, AllBlackAlbedoKeepsThePrior) {
  auto est = LightEstimator::create({});
  ASSERT_TRUE(est.ok());
  const ShRgb before = est->filtered();
  LightSystem sys;
  ShVector zero{};
  for (int p = 0; p < 1000; ++p) sys.add(zero, glm::dvec3(0.0));
  auto r = est->update(sys, 0, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->valid);
  EXPECT_EQ(r->confidence, 0.0f);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(est->filtered()[i].x, before[i].x, 1e-12);
  EXPECT_GT(est->filtered()[0].x, 0.0);  // the prior ambient is still there
}

TEST(SsrtLightEstimation, HdrUpToAMillionStaysFiniteAndScalesLinearly) {
  const SampleSets sets = samples(32);
  ShRgb lit = sh_directional_light(glm::normalize(glm::dvec3(1, 1, 0)), glm::dvec3(1.0));
  lit[0] += glm::dvec3(0.1);
  LightEstimatorSettings s;
  s.relative_regularisation = 1e-9;
  auto a = LightEstimator::create(s);
  auto b = LightEstimator::create(s);
  ASSERT_TRUE(a.ok() && b.ok());
  ShRgb hdr = lit;
  for (auto& c : hdr) c *= 1e6;
  ASSERT_TRUE(a->update(synthetic_frame(sets, lit, 0.5, 2000, 2), 0, 0.0).ok());
  auto r = b->update(synthetic_frame(sets, hdr, 0.5, 2000, 2), 0, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(is_finite(b->filtered()));
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(b->filtered()[i].y / 1e6, a->filtered()[i].y, 1e-4);
  for (auto c : r->sh_radiance) EXPECT_TRUE(std::isfinite(c[0]) && std::isfinite(c[2]));
  EXPECT_TRUE(std::isfinite(r->dominant_intensity[0]));
  EXPECT_GT(r->dominant_intensity[0], 1e5f);
}

TEST(SsrtLightEstimation, NonFiniteSystemIsRefusedAndTheEstimateKept) {
  auto est = LightEstimator::create({});
  ASSERT_TRUE(est.ok());
  const ShRgb before = est->filtered();
  LightSystem sys;
  sys.ata[5] = std::nan("");
  auto r = est->update(sys, 3, 0.1);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::BadInput);
  EXPECT_NE(r.error().message.find("frame 3"), std::string::npos);
  LightSystem inf;
  inf.atb[0] = INFINITY;
  EXPECT_FALSE(est->update(inf, 4, 0.2).ok());
  for (int i = 0; i < 16; ++i) EXPECT_EQ(est->filtered()[i].x, before[i].x);
}

TEST(SsrtLightEstimation, TemporalFilterConvergesWithItsLagInFrames) {
  const SampleSets sets = samples(32);
  const ShRgb first = sh_directional_light(glm::dvec3(0, 1, 0), glm::dvec3(1.0));
  const ShRgb second = sh_directional_light(glm::dvec3(1, 0, 0), glm::dvec3(3.0));
  LightEstimatorSettings s;
  s.relative_regularisation = 1e-9;
  s.lag_frames = 15.0;
  auto est = LightEstimator::create(s);
  ASSERT_TRUE(est.ok());
  ASSERT_TRUE(est->update(synthetic_frame(sets, first, 0.5, 1500, 1), 0, 0.0).ok());
  const double start = est->filtered()[3].y;  // band 1, x
  const LightSystem sys2 = synthetic_frame(sets, second, 0.5, 1500, 1);
  ASSERT_TRUE(est->update(sys2, 1, 1.0 / 30.0).ok());  // one step to measure the target
  const double target = est->frame_solution()[3].y;
  auto remaining = [&] { return (est->filtered()[3].y - target) / (start - target); };
  // After one frame: exp(-1/15).
  EXPECT_NEAR(remaining(), std::exp(-1.0 / 15.0), 1e-6);
  for (int f = 2; f <= 15; ++f) ASSERT_TRUE(est->update(sys2, f, f / 30.0).ok());
  EXPECT_NEAR(remaining(), std::exp(-1.0), 1e-6);  // one lag: 15 frames
  for (int f = 16; f <= 160; ++f) ASSERT_TRUE(est->update(sys2, f, f / 30.0).ok());
  EXPECT_LT(std::abs(remaining()), 1e-4);
  // Solves 4 frames apart (the light stage's interleaved system): the same lag in frames.
  auto est3 = LightEstimator::create(s);
  ASSERT_TRUE(est3->update(synthetic_frame(sets, first, 0.5, 1500, 1), 0, 0.0).ok());
  for (int f = 4; f <= 16; f += 4) ASSERT_TRUE(est3->update(sys2, f, 99.0).ok());
  EXPECT_NEAR((est3->filtered()[3].y - target) / (start - target), std::exp(-16.0 / 15.0), 1e-6);
  // Timestamps that do not advance do not freeze the filter: it steps by frame index.
  auto est2 = LightEstimator::create(s);
  ASSERT_TRUE(est2->update(synthetic_frame(sets, first, 0.5, 1500, 1), 0, 5.0).ok());
  for (int f = 1; f <= 300; ++f) ASSERT_TRUE(est2->update(sys2, f, 5.0).ok());
  EXPECT_NEAR(est2->filtered()[3].y, target, 1e-3 * std::abs(target));
}

TEST(SsrtLightEstimation, SettingsOutOfRangeNameTheField) {
  LightEstimatorSettings s;
  s.bands = 5;
  auto e = LightEstimator::create(s);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(e.error().message.find("bands"), std::string::npos);
  s = {};
  s.gray_albedo = 0.0;
  e = LightEstimator::create(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("gray_albedo"), std::string::npos);
  s = {};
  s.min_regularisation = 0.0;
  EXPECT_FALSE(LightEstimator::create(s).ok());
}

TEST(SsrtLightEstimation, FewerBandsSolveOnlyThoseCoefficients) {
  const SampleSets sets = samples(32);
  ShRgb lit = sh_directional_light(glm::dvec3(0, 1, 0), glm::dvec3(2.0), 2);
  lit[0] += glm::dvec3(0.3);
  LightEstimatorSettings s;
  s.bands = 2;
  s.relative_regularisation = 1e-9;
  auto est = LightEstimator::create(s);
  ASSERT_TRUE(est.ok());
  auto r = est->update(synthetic_frame(sets, lit, 0.5, 2000, 8), 0, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->bands, 2);
  for (int i = 4; i < 16; ++i) EXPECT_EQ(r->sh_radiance[i][1], 0.0f);
  EXPECT_NEAR(r->direction_to_light[1], 1.0f, 1e-2f);
}

// A 4-band estimator fed a level's 2-band transfer (a level with sh_bands 2): only 4 coefficients
// are solved, the others come out 0; more bands than the estimator has are refused.
TEST(SsrtLightEstimation, SolveBandsOfTheFrameLimitTheSolve) {
  const SampleSets sets = samples(32);
  ShRgb lit = sh_directional_light(glm::dvec3(0, 1, 0), glm::dvec3(2.0), 2);
  lit[0] += glm::dvec3(0.3);
  auto est = LightEstimator::create({});
  ASSERT_TRUE(est.ok());
  auto r = est->update(synthetic_frame(sets, lit, 0.5, 2000, 8), 0, 0.0, 2);
  ASSERT_TRUE(r.ok());
  for (int i = 4; i < 16; ++i) EXPECT_EQ(est->frame_solution()[i].y, 0.0) << i;
  EXPECT_GT(r->direction_to_light[1], 0.95f);
  auto bad = est->update(synthetic_frame(sets, lit, 0.5, 100, 8), 1, 0.1, 5);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("solve_bands"), std::string::npos);
}

}  // namespace
