// The light stage's parts on the CPU: median-cut environment sampling (energy, the sun's
// direction and irradiance, stability under sensor noise, fisheye input), the ambient as
// irradiance matrices, the stage's split of an environment into shadowed lights and ambient,
// and the probeless estimate of a rendered room corner (direction and colour of its sun).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <random>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "light/env_sampler.h"
#include "light/light_stage.h"
#include "light/probeless.h"
#include "light/sh_tools.h"
#include "mrgi/platform/capture.h"

namespace {
using namespace mrgi;
using namespace mrgi::light;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) / kDeg;
}

// Equirectangular direction of pixel (u, v) of a w x h image (light_from_environment's mapping).
glm::dvec3 equirect_direction(int u, int v, int w, int h) {
  const double theta = (v + 0.5) / h * kPi, phi = ((u + 0.5) / w - 0.5) * 2.0 * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

// A sky of radiance `sky` over the upper hemisphere (a floor's worth of nothing below) and a sun
// disc of `sun_radius_deg` towards `sun` whose irradiance at normal incidence is `sun_e`.
struct Sky {
  glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, 0.7, -0.3));
  glm::dvec3 sky{0.10, 0.15, 0.25};
  glm::dvec3 sun_e{3.0, 2.7, 2.2};
  double sun_radius_deg = 3.0;
  ImageRGBF image(int w = 256, int h = 128) const {
    ImageRGBF img(w, h);
    const double cos_r = std::cos(sun_radius_deg * kDeg);
    const double sun_solid_angle = 2.0 * kPi * (1.0 - cos_r);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const glm::dvec3 d = equirect_direction(u, v, w, h);
        glm::dvec3 l = d.y > 0.0 ? sky : glm::dvec3(0.0);
        if (glm::dot(d, sun) >= cos_r) l += sun_e / sun_solid_angle * disc_scale(w, h);
        float* t = img.at(u, v);
        t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z);
      }
    return img;
  }
  // The disc's pixels (by pixel centre) cover another solid angle than the analytic disc:
  // their radiance is scaled so they carry exactly sun_e.
  double disc_scale(int w, int h) const {
    const double cos_r = std::cos(sun_radius_deg * kDeg);
    double covered = 0.0;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u)
        if (glm::dot(equirect_direction(u, v, w, h), sun) >= cos_r)
          covered += std::sin((v + 0.5) / h * kPi) * (kPi / h) * (2.0 * kPi / w);
    return covered > 0.0 ? 2.0 * kPi * (1.0 - cos_r) / covered : 1.0;
  }
  // Total irradiance the image's pixels carry (sum L dw), which the cut must conserve.
  static glm::dvec3 energy(const ImageRGBF& img) {
    glm::dvec3 sum(0.0);
    for (int v = 0; v < img.height; ++v)
      for (int u = 0; u < img.width; ++u) {
        const double theta = (v + 0.5) / img.height * kPi;
        const double dw = std::sin(theta) * (kPi / img.height) * (2.0 * kPi / img.width);
        const float* t = img.at(u, v);
        sum += glm::dvec3(t[0], t[1], t[2]) * dw;
      }
    return sum;
  }
};

TEST(EnvSampler, MedianCutConservesEnergyAndFindsTheSun) {
  const Sky sky;
  const ImageRGBF img = sky.image();
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE(s->update(img, EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  ASSERT_EQ(s->lights().size(), 16u);
  glm::dvec3 total(0.0);
  double solid = 0.0;
  for (const EnvLight& l : s->lights()) {
    total += l.irradiance;
    solid += l.solid_angle_sr;
  }
  const glm::dvec3 expected = Sky::energy(img);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(total[c], expected[c], 1e-3 * expected[c]);
  EXPECT_NEAR(solid, 4.0 * kPi, 1e-6);
  // The strongest light is (part of) the sun: the cut divides the sun itself, whose energy
  // outweighs the sky's, so the lights within a few degrees of it hold its irradiance plus the
  // little sky their regions hold.
  const EnvLight& top = s->lights()[0];
  EXPECT_LT(angle_deg(top.direction, sky.sun), 2.0);
  glm::dvec3 near_sun(0.0);
  for (const EnvLight& l : s->lights())
    if (angle_deg(l.direction, sky.sun) < 5.0) near_sun += l.irradiance;
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(near_sun[c], 0.98 * sky.sun_e[c]);
    EXPECT_LE(near_sun[c], 1.15 * sky.sun_e[c]);
  }
  // Every region holds about the same energy (the median cut's invariant), up to the sun's
  // indivisible cells.
  for (size_t k = 1; k < s->lights().size(); ++k)
    EXPECT_LE(luminance(s->lights()[k].irradiance), luminance(top.irradiance) + 1e-9);
}

TEST(EnvSampler, SplitLightCarriesTheCutOnInsideItsRegion) {
  const Sky sky;
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE(s->update(sky.image(), EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  std::array<EnvPart, 4> parts{};
  double widest = 0.0;
  for (size_t k = 0; k < s->lights().size(); ++k) {
    const EnvLight& l = s->lights()[k];
    ASSERT_EQ(s->split_light(k, 4, parts.data()), 4);
    glm::dvec3 sum(0.0);
    double solid = 0.0, spread = 0.0;
    for (const EnvPart& p : parts) {
      sum += p.irradiance;
      solid += p.solid_angle_sr;
      spread = std::max(spread, angle_deg(p.direction, l.direction));
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], l.irradiance[c], 1e-9 * (1.0 + l.irradiance[c])) << k;
    EXPECT_NEAR(solid, l.solid_angle_sr, 1e-9) << k;
    if (l.solid_angle_sr > 0.5) widest = std::max(widest, spread);
  }
  // A broad region's parts spread over it (the point of splitting it): the sky's broad regions
  // span tens of degrees.
  EXPECT_GT(widest, 5.0);
  // The halving is the cut's: a uniform environment as one region falls into four lunes of 90
  // degrees of azimuth, equal in light, their lights on the horizon 90 degrees apart.
  ImageRGBF uniform = sky.image();
  for (float& v : uniform.data) v = 1.0f;
  EnvSamplerSettings one;
  one.samples = 1;
  auto u = EnvSampler::create(one);
  ASSERT_TRUE(u.ok());
  ASSERT_TRUE(u->update(uniform, EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  ASSERT_EQ(u->lights().size(), 1u);
  ASSERT_EQ(u->split_light(0, 4, parts.data()), 4);
  const double each = luminance(u->lights()[0].irradiance) / 4.0;
  for (size_t i = 0; i < parts.size(); ++i) {
    EXPECT_NEAR(luminance(parts[i].irradiance), each, 1e-6 * each) << i;
    EXPECT_NEAR(parts[i].direction.y, 0.0, 1e-6) << i;
    EXPECT_NEAR(parts[i].solid_angle_sr, kPi, 1e-6) << i;
    for (size_t j = 0; j < i; ++j) EXPECT_GT(angle_deg(parts[i].direction, parts[j].direction), 89.0) << i << " " << j;
  }
  // A single cell stands for every part, with an equal share of its light: a cut of more
  // regions than the grid has cells leaves some at one cell (the polar row's cells: 0.230 sr).
  EnvSamplerSettings cells;
  cells.grid_width = 8;
  cells.samples = 64;
  auto c = EnvSampler::create(cells);
  ASSERT_TRUE(c.ok()) << c.error().message;
  ASSERT_TRUE(c->update(sky.image(), EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  size_t cell = 0;
  for (size_t k = 1; k < c->lights().size(); ++k)
    if (c->lights()[k].solid_angle_sr < c->lights()[cell].solid_angle_sr) cell = k;
  const EnvLight& single = c->lights()[cell];
  ASSERT_NEAR(single.solid_angle_sr, 2.0 * kPi * (1.0 - std::sqrt(0.5)) / 8.0, 1e-3);
  ASSERT_EQ(c->split_light(cell, 4, parts.data()), 4);
  for (const EnvPart& p : parts) {
    EXPECT_LT(angle_deg(p.direction, single.direction), 1e-6);
    EXPECT_NEAR(luminance(p.irradiance), 0.25 * luminance(single.irradiance), 1e-9 * luminance(single.irradiance));
  }
  // Refused: a count not a power of two, a light that is not there.
  EXPECT_EQ(s->split_light(0, 3, parts.data()), 0);
  EXPECT_EQ(s->split_light(0, 0, parts.data()), 0);
  EXPECT_EQ(s->split_light(s->lights().size(), 4, parts.data()), 0);
}

TEST(EnvSampler, LightsStayPutUnderFrameNoise) {
  const Sky sky;
  const ImageRGBF clean = sky.image();
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok());
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.03f);  // 3 % per pixel, a noisy HDR camera
  std::vector<glm::dvec3> first;
  double worst = 0.0;
  for (int frame = 0; frame < 30; ++frame) {
    ImageRGBF img = clean;
    for (float& v : img.data) v *= std::max(0.0f, 1.0f + noise(rng));
    ASSERT_TRUE(s->update(img, EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
    if (frame == 0) {
      for (int k = 0; k < 4; ++k) first.push_back(s->lights()[size_t(k)].direction);
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      // Match each of the first frame's strongest lights to its nearest light now.
      double best = 180.0;
      for (const EnvLight& l : s->lights()) best = std::min(best, angle_deg(l.direction, first[size_t(k)]));
      worst = std::max(worst, best);
    }
  }
  EXPECT_LT(worst, 2.0) << "a strong light moved by " << worst << " degrees under 3 % noise";
  EXPECT_LT(angle_deg(s->lights()[0].direction, sky.sun), 1.0);
}

TEST(EnvSampler, FisheyeLookingUpSeesTheSunWhereItIs) {
  // An equidistant fisheye of 180 degrees looking straight up (+y), its image x along world +x.
  const Sky sky;
  const int size = 128;
  EnvCamera cam;
  cam.model = EnvModel::FisheyeEquidistant;
  cam.fov_deg = 180.0;
  cam.cx = cam.cy = 0.5 * (size - 1);
  cam.f = 0.5 * size / (0.5 * kPi);
  // Camera axes (OpenCV: x right, y down, z forward) -> world: x -> +x, y -> -z, z -> +y.
  const glm::dmat3 m(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  cam.rotation = glm::quat_cast(m);
  ImageRGBF img(size, size);
  const double cos_r = std::cos(sky.sun_radius_deg * kDeg);
  const double sun_solid_angle = 2.0 * kPi * (1.0 - cos_r);
  for (int v = 0; v < size; ++v)
    for (int u = 0; u < size; ++u) {
      const double dx = u - cam.cx, dy = v - cam.cy, r = std::sqrt(dx * dx + dy * dy);
      const double theta = r / cam.f;
      if (theta > 0.5 * kPi) continue;
      const glm::dvec3 d_cam = r > 0 ? glm::dvec3(std::sin(theta) * dx / r, std::sin(theta) * dy / r, std::cos(theta))
                                     : glm::dvec3(0, 0, 1);
      const glm::dvec3 d = m * d_cam;
      glm::dvec3 l = sky.sky;
      if (glm::dot(d, sky.sun) >= cos_r) l += sky.sun_e / sun_solid_angle;
      float* t = img.at(u, v);
      t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z);
    }
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE(s->update(img, cam, glm::dquat(1, 0, 0, 0)).ok());
  EXPECT_LT(angle_deg(s->lights()[0].direction, sky.sun), 2.0);
  // Nothing below the horizon: the fisheye does not see it.
  for (const EnvLight& l : s->lights()) {
    if (luminance(l.irradiance) > 1e-6) {
      EXPECT_GT(l.direction.y, -0.05);
    }
  }
}

// The grid's pyramid for cones wider than a cell (what dvct's specular cone reads of the
// environment): every level holds the grid's energy (sum of L dw with each level's exact cell
// solid angles) within 1 %, a uniform sky stays uniform, and the sun stays in its direction: the
// brightest cell of every level is the one holding the sun.
TEST(EnvSampler, ConePyramidKeepsTheEnergyAndTheSunsDirection) {
  const Sky sky;
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE(s->update(sky.image(), EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  std::vector<glm::vec4> cells;
  const int w0 = s->settings().grid_width;
  ASSERT_EQ(s->cone_pyramid(5, cells), 5);
  ASSERT_EQ(cells.size(), EnvSampler::cone_pyramid_cells(w0, 5));
  ASSERT_EQ(cells.size(), size_t(64 * 32 + 32 * 16 + 16 * 8 + 8 * 4 + 4 * 2));
  size_t first = 0;
  glm::dvec3 level0(0.0);
  for (int l = 0; l < 5; ++l) {
    const int w = w0 >> l, h = w / 2;
    glm::dvec3 energy(0.0);
    size_t brightest = first;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = first + size_t(y) * w + size_t(x);
        const double dw = (std::cos(kPi * y / h) - std::cos(kPi * (y + 1) / h)) * 2.0 * kPi / w;
        energy += glm::dvec3(cells[i]) * dw;
        if (cells[i].g > cells[brightest].g) brightest = i;
      }
    if (l == 0) level0 = energy;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(energy[c], level0[c], 0.01 * level0[c]) << "level " << l;
    const int bx = int(brightest - first) % w, by = int(brightest - first) / w;
    const glm::dvec3 centre = equirect_direction(bx, by, w, h);
    EXPECT_LT(angle_deg(centre, sky.sun), 0.75 * 180.0 / h + 1.0) << "level " << l;
    first += size_t(w) * size_t(h);
  }
  auto flat = EnvSampler::create({});
  ASSERT_TRUE(flat.ok());
  ASSERT_TRUE(flat->update(ImageRGBF(128, 64, 0.25f), EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  ASSERT_EQ(flat->cone_pyramid(5, cells), 5);
  for (const glm::vec4& c : cells) EXPECT_NEAR(c.r, 0.25f, 1e-4f);
}

TEST(EnvSampler, RefusesBadSettingsAndImages) {
  EXPECT_FALSE(EnvSampler::create({63, 16, 2.0}).ok());
  EXPECT_FALSE(EnvSampler::create({64, 12, 2.0}).ok());
  EXPECT_FALSE(EnvSampler::create({64, 16, -1.0}).ok());
  auto s = EnvSampler::create({});
  ASSERT_TRUE(s.ok());
  EXPECT_FALSE(s->update(ImageRGBF{}, EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  EnvCamera fisheye;
  fisheye.model = EnvModel::FisheyeEquidistant;
  EXPECT_FALSE(s->update(ImageRGBF(8, 8), fisheye, glm::dquat(1, 0, 0, 0)).ok());
  // NaN and negative texels count as nothing.
  ImageRGBF img(16, 8, 0.5f);
  img.data[0] = std::nanf("");
  img.data[5] = -3.0f;
  ASSERT_TRUE(s->update(img, EnvCamera{}, glm::dquat(1, 0, 0, 0)).ok());
  for (const EnvLight& l : s->lights()) EXPECT_TRUE(std::isfinite(l.irradiance.x));
}

TEST(IrradianceMatrices, AgreeWithTheShIrradiance) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    ShRgb l{};
    for (auto& c : l) c = glm::dvec3(u(rng), u(rng), u(rng));
    const auto m = irradiance_matrices(l);
    for (int k = 0; k < 50; ++k) {
      const glm::vec3 n = glm::normalize(glm::vec3(float(u(rng)), float(u(rng)), float(u(rng))));
      const glm::dvec3 e = sh_irradiance(l, n);
      const glm::vec4 n4(n, 1.0f);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::dot(n4, m[size_t(c)] * n4), e[c], 1e-4);
    }
  }
}

// The stage's lights plus its ambient must reproduce the environment's irradiance for any
// normal: the lights as deltas (what shading sees, unshadowed here), the ambient as SH.
glm::dvec3 stage_irradiance(const Lighting& lit, const glm::dvec3& n) {
  glm::dvec3 e = sh_irradiance(lit.ambient_real, glm::vec3(n));
  e = glm::max(e, glm::dvec3(0.0));
  for (const LightDesc& l : lit.lights)
    e += glm::dvec3(l.color) * double(l.intensity) * std::max(0.0, glm::dot(n, -glm::dvec3(l.direction)));
  return e;
}

TEST(LightStage, EnvironmentSplitsIntoShadowedLightsAndAmbientThatKeepTheIrradiance) {
  const Sky sky;
  const std::string path = ::testing::TempDir() + "light_stage_sky.exr";
  ASSERT_TRUE(write_exr(path, sky.image()).ok());
  SceneDesc scene;
  scene.environment.present = true;
  scene.environment.image = path;
  auto stage = LightStage::create({}, scene, CameraSetup{});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  const Lighting& lit = (*stage)->lighting();
  EXPECT_EQ(lit.source, LightSourceKind::Environment);
  ASSERT_EQ(lit.lights.size(), 4u);
  EXPECT_LT(angle_deg(-glm::dvec3(lit.lights[0].direction), sky.sun), 1.0);
  // Truth: the sun's cosine plus the sky's (upper hemisphere, radiance L: pi L (1 + n.y) / 2).
  for (const glm::dvec3 n : {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(1, 1, 0)),
                             glm::dvec3(0, 0, -1), glm::normalize(glm::dvec3(-0.3, 0.8, 0.5))}) {
    const glm::dvec3 truth = sky.sun_e * std::max(0.0, glm::dot(n, sky.sun)) + kPi * sky.sky * 0.5 * (1.0 + n.y);
    const glm::dvec3 got = stage_irradiance(lit, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], truth[c], 0.06 * luminance(truth) + 0.01) << n.x << " " << n.y << " " << n.z;
  }
  // The exported estimate: the sun's direction, and the light's colour (the sky's blue and
  // the sun's warm white together).
  EXPECT_LT(angle_deg(glm::dvec3(lit.estimate.direction_to_light[0], lit.estimate.direction_to_light[1],
                                 lit.estimate.direction_to_light[2]), sky.sun), 10.0);
  EXPECT_TRUE(lit.estimate.valid);
}

TEST(LightStage, UniformEnvironmentLightsAnUpFacingSurfaceLikeTheMean) {
  // The baseline test scene's case: radiance L all round; every surface gets pi L. The four
  // shadowed regions are a quarter of the sphere each drawn as one direction: within 8 %.
  const std::string path = ::testing::TempDir() + "light_stage_uniform.exr";
  ASSERT_TRUE(write_exr(path, ImageRGBF(64, 32, 0.05f)).ok());
  SceneDesc scene;
  scene.environment.present = true;
  scene.environment.image = path;
  auto stage = LightStage::create({}, scene, CameraSetup{});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  for (const glm::dvec3 n : {glm::dvec3(0, 1, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0)}) {
    const glm::dvec3 e = stage_irradiance((*stage)->lighting(), n);
    EXPECT_NEAR(e.y, kPi * 0.05, 0.08 * kPi * 0.05) << n.x << " " << n.y << " " << n.z;
  }
}

}  // namespace

static const glm::dvec3 kCapDirection = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));

// An environment of uniform radiance 0.1 with a cap of half-angle `cap_deg` around
// kCapDirection at `contrast` times it, as an equirectangular file, lit through the stage
// (`settings`); the stage's lighting.
static std::optional<Lighting> lighting_of(double cap_deg, double contrast, const std::string& name,
                                           const LightStageSettings& settings = {}) {
  const int w = 256, h = 128;
  ImageRGBF img(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const double l =
          glm::dot(equirect_direction(u, v, w, h), kCapDirection) >= std::cos(cap_deg * kDeg) ? 0.1 * contrast : 0.1;
      float* t = img.at(u, v);
      t[0] = t[1] = t[2] = float(l);
    }
  const std::string path = ::testing::TempDir() + name + ".exr";
  EXPECT_TRUE(write_exr(path, img).ok());
  SceneDesc scene;
  scene.environment.present = true;
  scene.environment.image = path;
  auto stage = LightStage::create(settings, scene, CameraSetup{});
  EXPECT_TRUE(stage.ok());
  if (!stage.ok()) return std::nullopt;
  return (*stage)->lighting();
}

// The broad bright parts of the ambient are kept as cones for the objects' occlusion
// (Lighting::ambient_regions, LightStageSettings::occlusion_region_min_contrast): a big bright
// window's regions, most concentrated first, pointing at it; none in a uniform environment once
// the rule asks for more than its mean; never a region that is a shadowed light.
TEST(LightStage, AmbientRegionsAreTheBroadBrightParts) {
  LightStageSettings cut;
  cut.occlusion_regions_from_sources = false;
  auto broad = lighting_of(30.0, 20.0, "regions_broad", cut);
  ASSERT_TRUE(broad);
  ASSERT_FALSE(broad->ambient_regions.empty());
  EXPECT_LE(broad->ambient_regions.size(), size_t(Lighting::kMaxOcclusionRegions));
  EXPECT_TRUE(broad->lights.empty());
  for (const Lighting::AmbientRegion& r : broad->ambient_regions) {
    EXPECT_LT(angle_deg(r.direction, kCapDirection), 30.0);  // inside the window's cone
    EXPECT_GT(r.half_angle_rad, 0.0);
    EXPECT_LT(r.half_angle_rad, 30.0 * kDeg);  // a median cut splits it
    EXPECT_GT(luminance(r.irradiance), 0.0);
  }
  LightStageSettings strict = cut;
  strict.occlusion_region_min_contrast = 2.0;
  auto uniform = lighting_of(0.0, 1.0, "regions_uniform", strict);
  ASSERT_TRUE(uniform);
  EXPECT_TRUE(uniform->ambient_regions.empty());
  auto still = lighting_of(30.0, 20.0, "regions_broad_strict", strict);
  ASSERT_TRUE(still);
  EXPECT_FALSE(still->ambient_regions.empty());
  // A compact bright source is a shadowed light, not also an ambient region.
  auto compact = lighting_of(6.0, 200.0, "regions_compact", cut);
  ASSERT_TRUE(compact);
  ASSERT_FALSE(compact->lights.empty());
  for (const Lighting::AmbientRegion& r : compact->ambient_regions)
    EXPECT_GT(angle_deg(r.direction, -glm::dvec3(compact->lights[0].direction)), 1e-3);
}

// By default the cones are the environment's light sources gathered whole
// (LightStageSettings::occlusion_regions_from_sources): a broad bright window is one cone
// pointing at its centre, as wide as it (not the median cut's pieces of it), holding its whole
// light; none where no cell stands out.
TEST(LightStage, AmbientRegionsAreTheEnvironmentsSourcesWhole) {
  auto broad = lighting_of(30.0, 20.0, "sources_broad");
  ASSERT_TRUE(broad);
  EXPECT_TRUE(broad->lights.empty());
  ASSERT_EQ(broad->ambient_regions.size(), size_t(1));
  const Lighting::AmbientRegion& r = broad->ambient_regions[0];
  EXPECT_LT(angle_deg(r.direction, kCapDirection), 1.0);
  EXPECT_NEAR(r.half_angle_rad / kDeg, 30.0, 2.5);  // the cap's own width, to a grid cell
  // Its whole light: the cap's radiance 2.0 times its solid angle 2 pi (1 - cos 30 deg).
  const double whole = 2.0 * 2.0 * kPi * (1.0 - std::cos(30.0 * kDeg));
  EXPECT_NEAR(r.irradiance.y, whole, 0.08 * whole);
  // The window is 2.0 / 0.227 = 8.8 times the environment's mean radiance (0.1 elsewhere).
  LightStageSettings strict;
  strict.occlusion_region_min_contrast = 10.0;
  auto none = lighting_of(30.0, 20.0, "sources_strict", strict);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->ambient_regions.empty());
  auto uniform = lighting_of(0.0, 1.0, "sources_uniform");
  ASSERT_TRUE(uniform);
  EXPECT_TRUE(uniform->ambient_regions.empty());  // no cell 3x the mean: no source
}

// The shadowed lights of lighting_of's environment.
static std::vector<LightDesc> shadowed_lights_of(double cap_deg, double contrast, const std::string& name) {
  auto lighting = lighting_of(cap_deg, contrast, name);
  if (!lighting) return {};
  for (const LightDesc& l : lighting->lights)
    EXPECT_LT(angle_deg(-glm::dvec3(l.direction), kCapDirection), 8.0) << name;  // a region holds some of the rest too
  return lighting->lights;
}

// The stage refuses settings of its environment rules that cannot work, naming them.
TEST(LightStage, RefusesBadEnvironmentRuleSettings) {
  SceneDesc scene;
  auto refused = [&](LightStageSettings s, const char* field) {
    auto stage = LightStage::create(s, scene, CameraSetup{});
    ASSERT_FALSE(stage.ok()) << field;
    EXPECT_NE(stage.error().message.find(field), std::string::npos) << stage.error().message;
  };
  LightStageSettings s;
  s.shadowed_max_solid_angle_sr = 0.0;
  refused(s, "shadowed_max_solid_angle_sr");
  s = {};
  s.lamp_removal.ring_outer_deg = s.lamp_removal.ring_inner_deg;
  refused(s, "lamp_removal");
  s = {};
  s.near_field_step_m = 0.0;
  refused(s, "near_field_step_m");
  s = {};
  s.occlusion_region_min_contrast = -1.0;
  refused(s, "occlusion_region_min_contrast");
  EXPECT_TRUE(LightStage::create({}, scene, CameraSetup{}).ok());
}

// Only compact, bright regions become shadowed lights (LightStageSettings::shadowed_min_contrast,
// shadowed_max_solid_angle_sr, EnvSamplerSettings::source_contrast); both sides of each rule.
TEST(LightStage, OnlyCompactBrightSourcesCastShadows) {
  const LightStageSettings d;
  // A 6-degree source (0.034 sr, under 0.05) far brighter than the rest: shadowed.
  EXPECT_FALSE(shadowed_lights_of(6.0, 200.0, "compact_bright").empty());
  // The same source too dim to stand out (contrast 2 < 3): ambient only.
  EXPECT_TRUE(shadowed_lights_of(6.0, 2.0, "compact_dim").empty());
  // A broad bright source, a lit wall near the env camera or a big window (30 degrees, 0.84 sr
  // > 0.05): ambient only, however its median cut splits it.
  EXPECT_TRUE(shadowed_lights_of(30.0, 20.0, "broad_bright").empty());
  // Just either side of the size limit: 7.0 degrees is 0.0469 sr, 7.5 is 0.0538 sr.
  ASSERT_NEAR(d.shadowed_max_solid_angle_sr, 0.05, 1e-12);
  EXPECT_FALSE(shadowed_lights_of(7.0, 200.0, "below_limit").empty());
  EXPECT_TRUE(shadowed_lights_of(7.5, 200.0, "above_limit").empty());
  // A uniform environment has nothing to shadow.
  EXPECT_TRUE(shadowed_lights_of(0.0, 1.0, "uniform").empty());
}

namespace {
// The env camera source end to end: the suite's fisheye capture (capture.json env_camera, env/
// frames) gives the stage its lights per frame, named in the note, the sun among them.
TEST(LightStage, EnvCameraFramesLightTheScene) {
  auto cap = mrgi::CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/perf/suite/env_fisheye");
  ASSERT_TRUE(cap.ok()) << cap.error().message;
  const mrgi::CaptureInfo& info = cap->info();
  ASSERT_TRUE(cap->scene() && cap->scene()->environment.from_env_camera);
  auto stage = LightStage::create({}, *cap->scene(),
                                  CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  auto f = cap->read_frame(0);
  ASSERT_TRUE(f.ok() && f->env && f->pose);
  std::vector<std::string> notes;
  ASSERT_TRUE((*stage)->update(frame::CameraView::of(*f, f->pose->matrix()), notes).ok());
  ASSERT_FALSE(notes.empty());
  // The courtyard's brightest parts (a hazy low sun, lit clouds) are broad, so none is a
  // shadowed light (LightStageSettings::shadowed_max_solid_angle_sr): all of it is ambient,
  // which the virtual objects occlude softly.
  EXPECT_EQ(notes.back(), "light: environment image (env camera, 16 median-cut regions, 0 shadowed)");
  const Lighting& lit = (*stage)->lighting();
  EXPECT_EQ(lit.source, LightSourceKind::Environment);
  EXPECT_EQ(lit.lights.size(), 0u);
  ASSERT_EQ((*stage)->environment_regions().size(), 16u);
  // One of the regions sits at the sun: the env image's brightest pixel, through the
  // equidistant model (r = f theta) and the env camera's rotation, within 10 degrees.
  const ImageRGBF& env = *f->env;
  int bu = 0, bv = 0;
  float best = -1.0f;
  for (int v = 0; v < env.height; ++v)
    for (int u = 0; u < env.width; ++u)
      if (const float l = env.at(u, v)[1]; l > best) {
        best = l;
        bu = u;
        bv = v;
      }
  const EnvCamera& cam = *info.env_camera;
  const double dx = bu - cam.cx, dy = bv - cam.cy, r = std::sqrt(dx * dx + dy * dy), theta = r / cam.f;
  const glm::dvec3 d_cam(std::sin(theta) * dx / r, std::sin(theta) * dy / r, std::cos(theta));
  const glm::dvec3 sun = glm::mat3_cast(cam.rotation) * d_cam;
  double closest = -1.0;
  for (const EnvLight& r : (*stage)->environment_regions()) closest = std::max(closest, glm::dot(r.direction, sun));
  EXPECT_GT(closest, std::cos(10.0 * kDeg));  // 6.7: the centroid of a region holding sky too
}
}  // namespace

namespace {
// A declared lamp changed at run time (LightStage::set_declared_lamp): the frame's lights and
// the exported estimate follow, the revision moves (maps are re-planned), a lamp scene.json would
// refuse or whose kind changes is refused; under a technique's own estimate (the probeless
// source) the lamp is kept but the frame's light is left as it is.
TEST(LightStage, DeclaredLampsChangeAtRunTime) {
  using namespace mrgi;
  using namespace mrgi::light;
  SceneDesc scene;
  LightDesc lamp;
  lamp.position = {0.0f, 2.0f, 0.0f};
  lamp.intensity = 2.0f;
  scene.lights.push_back(lamp);
  LightStageSettings settings;
  settings.residual_light = false;
  auto stage = LightStage::create(settings, scene, CameraSetup{});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  LightStage& s = **stage;
  const uint64_t revision = s.lighting().revision;
  const double lum_on = luminance(glm::dvec3(s.lighting().estimate.sh_radiance[0][0], s.lighting().estimate.sh_radiance[0][1],
                                             s.lighting().estimate.sh_radiance[0][2]));
  LightDesc off = lamp;
  off.intensity = 0.0f;
  ASSERT_TRUE(s.set_declared_lamp(0, off).ok());
  EXPECT_EQ(s.lighting().lights[0].intensity, 0.0f);
  EXPECT_GT(s.lighting().revision, revision);
  EXPECT_GT(lum_on, 0.0);
  EXPECT_EQ(s.lighting().estimate.sh_radiance[0][0], 0.0f);
  LightDesc bad = lamp;
  bad.type = LightType::Spot;
  EXPECT_EQ(s.set_declared_lamp(0, bad).error().kind, ErrorKind::BadUsage);
  bad = lamp;
  bad.color.x = -1.0f;
  EXPECT_EQ(s.set_declared_lamp(0, bad).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ(s.set_declared_lamp(1, lamp).error().kind, ErrorKind::BadUsage);

  // The probeless source of a technique's own estimate: the lamps light nothing.
  auto external = LightStage::create(settings, scene, CameraSetup{});
  ASSERT_TRUE(external.ok());
  (*external)->use_external_system();
  const size_t lights = (*external)->lighting().lights.size();
  const uint64_t ext_revision = (*external)->lighting().revision;
  ASSERT_TRUE((*external)->set_declared_lamp(0, off).ok());
  EXPECT_EQ((*external)->lighting().lights.size(), lights);
  EXPECT_EQ((*external)->lighting().revision, ext_revision);
  EXPECT_EQ((*external)->declared_lamp(0).intensity, 0.0f);
}
}  // namespace

namespace {
// The near-field rule (LightStageSettings::near_field_distance_m): a compact bright region the
// env camera sees is a shadowed light only when no surface of the depth image lies along its
// direction within 3 m of the env camera. A wall 1 m away in that direction: ambient; the same
// wall 5 m away, or a direction the depth camera cannot judge: a shadowed light.
TEST(LightStage, BrightNearSurfacesAreNotDistantLights) {
  const glm::dvec3 dir = glm::normalize(glm::dvec3(0.1, 0.05, 1.0));
  const int w = 128, h = 64;
  ImageRGBF env(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float l = glm::dot(equirect_direction(u, v, w, h), dir) >= std::cos(5.0 * kDeg) ? 20.0f : 0.1f;
      float* t = env.at(u, v);
      t[0] = t[1] = t[2] = l;
    }
  SceneDesc scene;
  scene.environment.present = true;
  scene.environment.from_env_camera = true;
  EnvCamera cam;  // equirectangular, world axes, at the origin
  cam.position = glm::dvec3(0.0);
  CameraSetup setup;
  setup.color = setup.depth = Intrinsics{64, 48, 50.0, 50.0, 31.5, 23.5};
  setup.depth_scale = 1000.0;
  setup.env_camera = cam;
  // The colour/depth camera 1 m behind the env camera, looking along +z (OpenCV axes = world).
  const glm::dmat4 camera_to_world = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -1.0));
  auto lights_with_wall_at = [&](double camera_depth_m) {
    auto stage = LightStage::create({}, scene, setup);
    EXPECT_TRUE(stage.ok());
    InputFrame f;
    f.env = env;
    f.color = ImageRGB8(64, 48, 128);
    f.depth = ImageU16(64, 48, uint16_t(camera_depth_m * 1000.0));
    std::vector<std::string> notes;
    EXPECT_TRUE((*stage)->update(frame::CameraView::of(f, camera_to_world), notes).ok());
    return (*stage)->lighting().lights.size();
  };
  EXPECT_EQ(lights_with_wall_at(2.0), 0u);   // the wall 1 m from the env camera: near
  EXPECT_GE(lights_with_wall_at(6.0), 1u);   // 5 m: beyond the near field
  EXPECT_GE(lights_with_wall_at(0.0), 1u);   // no measurement: nothing known to be near
  // Either side of the 3 m limit: the wall at 2.8 m and at 3.2 m from the env camera along z
  // (the region's direction is a few degrees off the cap's axis: the ray meets the wall a little
  // farther).
  EXPECT_EQ(lights_with_wall_at(3.8), 0u);
  EXPECT_GE(lights_with_wall_at(4.2), 1u);
}
}  // namespace

namespace {
// Which ambients already hold the real scene's bounce (Lighting::ambient_holds_real_bounce,
// ambient_below_from_camera): an env camera's image, whose unseen lower hemisphere is the colour
// camera's mean radiance, does (and not without that prior); an environment image file does not;
// the lamps' residual estimate holds it but not from the camera's view below.
TEST(LightStage, SaysWhetherItsAmbientHoldsTheRealBounce) {
  const int w = 64, h = 32;
  ImageRGBF env(w, h, 0.2f);
  CameraSetup setup;
  setup.color = setup.depth = Intrinsics{64, 48, 50.0, 50.0, 31.5, 23.5};
  setup.depth_scale = 1000.0;
  EnvCamera cam;
  cam.position = glm::dvec3(0.0);
  setup.env_camera = cam;
  auto lighting_after_a_frame = [&](const SceneDesc& scene, const LightStageSettings& settings) {
    auto stage = LightStage::create(settings, scene, setup);
    EXPECT_TRUE(stage.ok()) << (stage.ok() ? "" : stage.error().message);
    InputFrame f;
    if (scene.environment.from_env_camera) f.env = env;
    f.color = ImageRGB8(64, 48, 128);
    f.depth = ImageU16(64, 48, uint16_t(2000));
    std::vector<std::string> notes;
    EXPECT_TRUE((*stage)->update(frame::CameraView::of(f, glm::dmat4(1.0)), notes).ok());
    return (*stage)->lighting();
  };
  auto expect_flags = [](const Lighting& l, bool holds, bool below, const char* what) {
    EXPECT_EQ(l.ambient_holds_real_bounce, holds) << what;
    EXPECT_EQ(l.ambient_below_from_camera, below) << what;
  };
  SceneDesc camera_env;
  camera_env.environment.present = true;
  camera_env.environment.from_env_camera = true;
  expect_flags(lighting_after_a_frame(camera_env, {}), true, true, "env camera");
  LightStageSettings no_prior;
  no_prior.unseen_from_camera = false;
  expect_flags(lighting_after_a_frame(camera_env, no_prior), false, false, "env camera, dark below");
  const std::string path = ::testing::TempDir() + "light_stage_bounce_file.exr";
  ASSERT_TRUE(write_exr(path, env).ok());
  SceneDesc file_env;
  file_env.environment.present = true;
  file_env.environment.image = path;
  expect_flags(lighting_after_a_frame(file_env, {}), false, false, "environment file");
  SceneDesc lamps;
  LightDesc lamp;
  lamp.position = glm::vec3(0.0f, 1.0f, 1.0f);
  lamps.lights.push_back(lamp);
  const Lighting residual = lighting_after_a_frame(lamps, {});
  ASSERT_TRUE(residual.ambient_is_residual);
  expect_flags(residual, true, false, "residual estimate");
}
}  // namespace
