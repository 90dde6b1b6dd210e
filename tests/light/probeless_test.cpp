// The light stage's probeless source end to end on the CPU: a room corner (floor, two walls, a
// box) ray-traced under a coloured sun and a blue sky, seen by an RGB-D camera, estimated from
// colour and depth alone. Checks the dominant direction, the sun's colour, that the stage turns
// the estimate into one shadowed light plus ambient, and that bad frames are refused.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/look_at.h"
#include "image/srgb.h"
#include "light/light_stage.h"
#include "light/probeless.h"
#include "room_scene.h"

namespace {
using namespace mrgi;
using namespace mrgi::light;
using namespace mrgi::test_room;

TEST(Probeless, EstimatesTheSunsDirectionAndColourInARoomCorner) {
  const Room room;
  const RenderedFrame f = render(room, {1.6, 1.3, -0.9}, {0.1, 0.25, 1.0}, 320, 240);
  SceneDesc nothing;  // no lamp, no environment: the probeless source
  CameraSetup cams{f.k, f.k, 5000.0, 1.0, std::nullopt};
  LightStageSettings settings;
  auto stage = LightStage::create(settings, nothing, cams);
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  EXPECT_EQ((*stage)->planned_source(), LightSourceKind::Probeless);
  std::vector<std::string> notes;
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE((*stage)->update(frame::CameraView::of(f.frame, f.pose), notes).ok());
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const Lighting& lit = (*stage)->lighting();
  ASSERT_TRUE(lit.estimate.valid);
  const glm::dvec3 dir(lit.estimate.direction_to_light[0], lit.estimate.direction_to_light[1],
                       lit.estimate.direction_to_light[2]);
  // The truth's dominant direction: band 1 of sun + sky (the sky pulls it towards +y).
  ShRgb truth = sh_directional_light(room.sun, room.sun_e);
  for (int k = 0; k < 4000; ++k) {
    const glm::dvec3 w = fibonacci_direction(k, 4000);
    if (w.y <= 0.0) continue;
    const ShVector y = sh_basis(glm::vec3(w));
    for (int i = 0; i < kMaxShCoeffs; ++i) truth[size_t(i)] += room.sky * double(y[size_t(i)]) * (4.0 * kPi / 4000);
  }
  glm::dvec3 truth_dir;
  ASSERT_TRUE(sh_dominant_direction(truth, truth_dir));
  const double err = std::acos(std::clamp(glm::dot(dir, truth_dir), -1.0, 1.0)) * 180.0 / kPi;
  std::printf("probeless: direction error %.1f deg, confidence %.2f, %.1f ms for the whole system (%d x %d samples)\n",
              err, double(lit.estimate.confidence), ms, 80, 60);
  // The view shows three orientations (floor, two walls; the box's faces repeat them), so the
  // light's direction rests on the box's shadow and the priors (measured: 27 degrees). The
  // bound catches a broken estimator (a sign or axis error gives 90-180), not its accuracy,
  // which the light family measures on path-traced scenes (perf/results/light-family/light-family.md).
  EXPECT_LT(err, 35.0);
  // The light's colour (band 0 and the dominant light) within 10 % per channel of the truth's,
  // each normalised by its luminance: the estimate is RGB, not grey.
  const glm::dvec3 t0c = truth[0] / luminance(truth[0]), e0c = glm::dvec3(
      lit.estimate.sh_radiance[0][0], lit.estimate.sh_radiance[0][1], lit.estimate.sh_radiance[0][2]);
  const glm::dvec3 e0 = e0c / luminance(e0c);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e0[c], t0c[c], 0.1 * t0c[c]) << "channel " << c;
  // One shadowed dominant light, pointing from the light (scene.json's direction convention).
  ASSERT_EQ(lit.lights.size(), 1u);
  EXPECT_EQ(lit.lights[0].type, LightType::Directional);
  EXPECT_TRUE(lit.lights[0].real);
  EXPECT_GT(glm::dot(-glm::dvec3(lit.lights[0].direction), dir), 0.999);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("probeless"), std::string::npos) << notes.back();
}

// The residual light with a declared lamp (LightStageSettings::residual_light): the room lit by
// a point lamp and a sky of uniform radiance over the upper hemisphere; the lamp declared, the
// sky not. The lamp's light is taken off each sample, so the estimate's mean radiance (band 0)
// is the sky's: its band-0 coefficient is sky * Y_0 * 2 pi. Without a sky the residual is near
// 0 (what is left is the lamp's model error: its shadows outside the depth grid).
// A lagged view of the camera (frames given as the app's images: frame/camera_view.h) has no
// images for the first frames: the estimate waits, saying so, and comes from the first view with
// images, stamped with that frame's index and timestamp (not the frame being lit).
TEST(Probeless, AnEmptyCameraViewWaitsAndTheEstimateIsStampedWithTheViewsFrame) {
  const Room room;
  const RenderedFrame f = render(room, {1.6, 1.3, -0.9}, {0.1, 0.25, 1.0}, 160, 120);
  SceneDesc nothing;
  auto stage = LightStage::create({}, nothing, CameraSetup{f.k, f.k, 5000.0, 1.0, std::nullopt});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  std::vector<std::string> notes;
  frame::CameraView empty;
  empty.index = 7;
  ASSERT_TRUE((*stage)->update(empty, notes).ok());
  EXPECT_FALSE((*stage)->lighting().estimate.valid);
  ASSERT_GE(notes.size(), 2u);
  EXPECT_NE(notes[0].find("no camera frame readable on the host yet"), std::string::npos) << notes[0];
  frame::CameraView view = frame::CameraView::of(f.frame, f.pose);
  view.index = 5;  // the frame two before the one being lit
  view.timestamp = 0.25;
  notes.clear();
  ASSERT_TRUE((*stage)->update(view, notes).ok());
  const LightEstimate& e = (*stage)->lighting().estimate;
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.frame_index, 5);
  EXPECT_DOUBLE_EQ(e.timestamp, 0.25);
}

TEST(Probeless, ResidualLightBesideADeclaredLampIsTheUndeclaredSky) {
  for (const bool with_sky : {true, false}) {
    Room room;
    room.sun_e = glm::dvec3(0.0);
    room.lamp_intensity = glm::dvec3(1.5);
    room.sky = with_sky ? glm::dvec3(0.08) : glm::dvec3(0.0);
    // Every surface at the gray-world albedo the estimate assumes (0.5, the floor's): another
    // albedo is read as light (a wall of 0.6 under the lamp alone left a residual of a sixth of
    // this test's sky), which is the assumption's error, not the subtraction's.
    room.left_wall_albedo = room.back_wall_albedo = room.box_albedo = glm::dvec3(0.5);
    const RenderedFrame f = render(room, {1.6, 1.3, -0.9}, {0.1, 0.25, 1.0}, 320, 240);
    SceneDesc scene;
    LightDesc lamp;
    lamp.type = LightType::Point;
    lamp.position = glm::vec3(room.lamp_position);
    lamp.intensity = 1.5f;
    scene.lights.push_back(lamp);
    CameraSetup cams{f.k, f.k, 5000.0, 1.0, std::nullopt};
    for (const bool residual : {true, false}) {
      LightStageSettings settings;
      settings.residual_light = residual;
      auto stage = LightStage::create(settings, scene, cams);
      ASSERT_TRUE(stage.ok()) << stage.error().message;
      EXPECT_EQ((*stage)->planned_source(), LightSourceKind::Declared);
      std::vector<std::string> notes;
      ASSERT_TRUE((*stage)->update(frame::CameraView::of(f.frame, f.pose), notes).ok());
      const Lighting& lit = (*stage)->lighting();
      EXPECT_EQ(lit.lights.size(), 1u);  // the lamp; the residual is ambient, not a light
      EXPECT_EQ(lit.ambient_is_residual, residual);
      ASSERT_FALSE(notes.empty());
      EXPECT_EQ(notes.back().find("residual") != std::string::npos, residual) << notes.back();
      const double c0 = luminance(lit.ambient_real[0]);
      const double truth = with_sky ? 0.08 * 0.282094791773878 * 2.0 * kPi : 0.0;
      std::printf("residual %s, sky %s: band 0 %.4f (truth %.4f; the fit's own %.4f)\n", residual ? "on" : "off",
                  with_sky ? "on" : "off", c0, truth, luminance((*stage)->estimator().filtered()[0]));
      if (!residual) {
        EXPECT_EQ(c0, 0.0);
        continue;
      }
      // Only the mean is kept (residual_shading_bands 1).
      for (int i = 1; i < kMaxShCoeffs; ++i) EXPECT_EQ(lit.ambient_real[size_t(i)], glm::dvec3(0.0));
      // With the sky: within a fifth of it (0.119 against 0.142: the walls hide part of the sky
      // from the floor, and the transfer sees them only where they are in the depth image, so
      // it reads the sky low). Without: the fit within 2 % of that sky either way (-0.0017: the
      // lamp's light taken off is the lamp's light seen, shadows searched in the depth grid),
      // and what is kept at least 0.
      const double sky_c0 = 0.08 * 0.282094791773878 * 2.0 * kPi;
      if (with_sky) {
        EXPECT_NEAR(c0, truth, 0.2 * truth);
      } else {
        EXPECT_LT(std::abs(luminance((*stage)->estimator().filtered()[0])), 0.02 * sky_c0);
        EXPECT_GE(c0, 0.0);
      }
      // The exported estimate holds the lamp and the residual.
      EXPECT_GT(luminance(glm::dvec3(lit.estimate.sh_radiance[0][0], lit.estimate.sh_radiance[0][1],
                                     lit.estimate.sh_radiance[0][2])),
                c0 - 1e-9);
    }
  }
}

// A known failure of shipping estimators: on a static scene the intensity creeps towards zero
// over thousands of frames (a filter or prior that leaks). 10,000 frames of one view with fresh
// sensor noise each frame: the estimate's intensity and direction stay where they settled.
TEST(Probeless, NoDriftOverTenThousandFramesOfAStaticScene) {
  const Room room;
  const RenderedFrame clean = render(room, {1.6, 1.3, -0.9}, {0.1, 0.25, 1.0}, 32, 24);
  auto stage = LightStage::create({}, SceneDesc{}, CameraSetup{clean.k, clean.k, 5000.0, 1.0, std::nullopt});
  ASSERT_TRUE(stage.ok()) << stage.error().message;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> noise(-2, 2);
  InputFrame f = clean.frame;
  std::vector<std::string> notes;
  // Intensity and direction averaged over a window early on (after the filter settled) and over
  // the last one: the noise moves single frames by about a per cent, a drift moves the mean.
  constexpr int kWindow = 400;
  double lum_early = 0.0, lum_late = 0.0;
  glm::dvec3 dir_early(0.0), dir_late(0.0);
  for (int i = 0; i < 10000; ++i) {
    for (size_t k = 0; k < f.color.data.size(); ++k)
      f.color.data[k] = uint8_t(std::clamp(int(clean.frame.color.data[k]) + noise(rng), 0, 255));
    f.index = i;
    f.timestamp = i / 30.0;
    notes.clear();
    ASSERT_TRUE((*stage)->update(frame::CameraView::of(f, clean.pose), notes).ok());
    const LightEstimate& e = (*stage)->lighting().estimate;
    const double lum = luminance(glm::dvec3(e.sh_radiance[0][0], e.sh_radiance[0][1], e.sh_radiance[0][2]));
    const glm::dvec3 dir(e.direction_to_light[0], e.direction_to_light[1], e.direction_to_light[2]);
    if (i >= 200 && i < 200 + kWindow) {
      lum_early += lum / kWindow;
      dir_early += dir;
    } else if (i >= 10000 - kWindow) {
      lum_late += lum / kWindow;
      dir_late += dir;
    }
  }
  ASSERT_GT(lum_early, 0.0);
  EXPECT_NEAR(lum_late, lum_early, 0.01 * lum_early) << "intensity drifted over 10,000 frames";
  EXPECT_GT(glm::dot(glm::normalize(dir_late), glm::normalize(dir_early)), std::cos(1.0 * kPi / 180.0))
      << "direction drifted";
}

// ProbelessSettings::grey_vote (off by default, see there): a red wall beside a grey floor
// turns gray-world's light red; the vote keeps it the light's colour.
TEST(Probeless, ColourVoteIgnoresAMinorityRedWall) {
  Room room;
  room.sun_e = glm::dvec3(2.0);
  room.sky = glm::dvec3(0.1);  // white light: the truth's colour is grey
  room.left_wall_albedo = glm::dvec3(0.7, 0.1, 0.08);
  const RenderedFrame f = render(room, {1.6, 1.3, -0.9}, {0.1, 0.25, 1.0}, 160, 120);
  auto colour_error = [&](bool vote) {
    LightStageSettings s;
    s.probeless.grey_vote = vote;
    auto stage = LightStage::create(s, SceneDesc{}, CameraSetup{f.k, f.k, 5000.0, 1.0, std::nullopt});
    EXPECT_TRUE(stage.ok());
    std::vector<std::string> notes;
    EXPECT_TRUE((*stage)->update(frame::CameraView::of(f.frame, f.pose), notes).ok());
    const auto& b0 = (*stage)->lighting().estimate.sh_radiance[0];
    const glm::dvec3 c(b0[0], b0[1], b0[2]);
    const glm::dvec3 n = c / luminance(c);
    return std::max({std::abs(n.x - 1.0), std::abs(n.y - 1.0), std::abs(n.z - 1.0)});
  };
  const double gray_world = colour_error(false), voted = colour_error(true);
  std::printf("red wall: colour error gray-world %.2f, vote %.2f\n", gray_world, voted);
  EXPECT_GT(gray_world, 0.1);  // the wall tints the light (0.15 measured)
  EXPECT_LT(voted, 0.1);
}

TEST(Probeless, ASkyBeyondTheDepthSensorsRangeIsDistantLightAndANarrowDepthHoleIsNot) {
  const Room room;
  // Over the corner's walls (1.5 m high) from the open side: the sky fills the frame's top.
  const RenderedFrame f = render(room, {2.6, 1.0, -1.5}, {0.5, 1.4, 0.8}, 160, 120, true);
  ProbelessSettings ps;
  ps.parts = 1;
  auto b = ProbelessBuilder::create(ps, f.k, f.k, 5000);
  ASSERT_TRUE(b.ok()) << b.error().message;
  auto distant_bins = [&](const InputFrame& frame, const glm::dmat4& pose) {
    auto store = RadianceSamples::create({});
    EXPECT_TRUE(store.ok());
    LightSystem sys;
    EXPECT_TRUE(b->add_part(frame::CameraView::of(frame, pose), 1.0, 0, sys, &*store).ok());
    std::vector<RadianceSamples::DistantBin> seen;
    for (const auto& bin : store->distant_bins())
      if (bin.observations > 0) seen.push_back(bin);
    return seen;
  };
  const auto sky = distant_bins(f.frame, f.pose);
  std::printf("%zu distant bins seen\n", sky.size());
  EXPECT_GE(sky.size(), 6u);
  for (const auto& bin : sky) {
    EXPECT_GT(bin.direction.y, 0.0f) << "only the sky is beyond the room";
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(bin.colour[c], room.sky[c], 0.08 * room.sky[c]) << "channel " << c;
  }
  // A view of the floor alone with a 2-pixel line and a 3 x 3 spot of lost depth (what a sensor
  // drops along edges and on dark spots): no view of the distant light.
  RenderedFrame floor = render(room, {1.0, 1.2, -1.0}, {1.0, 0.0, 0.2}, 160, 120, true);
  for (int v = 0; v < 120; ++v) floor.frame.depth.at(70, v)[0] = floor.frame.depth.at(71, v)[0] = 0;
  for (int v = 50; v < 53; ++v)
    for (int u = 100; u < 103; ++u) floor.frame.depth.at(u, v)[0] = 0;
  EXPECT_TRUE(distant_bins(floor.frame, floor.pose).empty());
}

TEST(Probeless, RefusesFramesOfAnotherSizeAndBadSettings) {
  Intrinsics k{64, 48, 50, 50, 32, 24};
  EXPECT_FALSE(ProbelessBuilder::create({8, 64, 6, 0.6, 4}, k, k, 5000).ok());
  EXPECT_FALSE(ProbelessBuilder::create({80, 8, 6, 0.6, 4}, k, k, 5000).ok());
  EXPECT_FALSE(ProbelessBuilder::create({80, 64, 6, 0.0, 4}, k, k, 5000).ok());
  EXPECT_FALSE(ProbelessBuilder::create({80, 64, 6, 0.6, 0}, k, k, 5000).ok());
  ProbelessSettings margin;
  margin.distant_margin = 9;
  EXPECT_FALSE(ProbelessBuilder::create(margin, k, k, 5000).ok());
  auto b = ProbelessBuilder::create({}, k, k, 5000);
  ASSERT_TRUE(b.ok()) << b.error().message;
  InputFrame f;
  f.color = ImageRGB8(32, 24);
  f.depth = ImageU16(32, 24);
  LightSystem sys;
  EXPECT_FALSE(b->add_part(frame::CameraView::of(f, glm::dmat4(1.0)), 1.0, 0, sys).ok());
  f.color = ImageRGB8(64, 48);
  f.depth = ImageU16(64, 48);
  EXPECT_FALSE(b->add_part(frame::CameraView::of(f, glm::dmat4(1.0)), 1.0, 9, sys).ok());
  // An empty depth image: no sample, nothing added, no NaN.
  ASSERT_TRUE(b->add_part(frame::CameraView::of(f, glm::dmat4(1.0)), 1.0, 0, sys).ok());
  EXPECT_EQ(sys.samples, 0.0);
}

}  // namespace
