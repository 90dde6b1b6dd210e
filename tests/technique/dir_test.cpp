// The dir technique end to end on the synthetic scene (synthetic_scene.h) with Vulkan validation
// on (a message fails process()/flush()): every level runs, says what it does not build yet, and
// its VPLs light the virtual boxes beyond baseline's direct light at the same baseline level
// (the floor's bounce: the paper's VPL 1, L_r D_r D_v E). Stress: 1,000 frames stay
// finite and do not grow. Accuracy against path-traced references is the bench's (perf/).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/research.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "stress_run.h"
#include "synthetic_scene.h"
#include "technique/dir/dir.h"

namespace mrgi::test {
namespace {

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

std::vector<FrameOutput> run(const SyntheticScene& scene, const std::string& technique, int level, int frames,
                             bool validate, const DirAblation& ablation = {}, const std::vector<KnobSetting>& knobs = {}) {
  RuntimeSettings s;
  s.device.validate = validate;
  s.knobs = knobs;
  auto research = std::make_shared<ResearchSettings>();
  research->dir = ablation;
  s.research = research;
  s.technique = technique;
  s.level = level;
  return run_synthetic_frames(scene, s, frames);
}

// Mean linear light of the pixels the virtual boxes cover.
double virtual_light(const SyntheticScene& scene, const FrameOutput& out) {
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  double sum = 0.0;
  int n = 0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if (scene.trace(u, v, true).kind != SurfaceKind::Virtual) continue;
      const size_t o = (size_t(v) * w + u) * 4;
      for (int c = 0; c < 3; ++c) sum += lin(out.image.data[o + c]);
      ++n;
    }
  EXPECT_GT(n, 0);
  return sum / std::max(n, 1);
}

// The lamp aimed at the lamp-facing side of the virtual box C1, a 25 degree cone: that side
// then covers a fair share of the lamp's map, and of the VPLs (with the scene's 65 degree cone
// over the whole floor it gets about one in 200, and its bounce hardly shows).
void aim_at_the_virtual_box(SyntheticScene& scene) {
  const glm::vec3 target = 0.5f * (scene.virtual_boxes[0].lo + scene.virtual_boxes[0].hi);
  for (LightDesc* l : {&scene.lamp, &scene.scene.lights[0]}) {
    l->direction = glm::normalize(target - l->position);
    l->inner_angle_deg = 20.0f;
    l->outer_angle_deg = 25.0f;
  }
}

TEST(Dir, EveryLevelRunsAndItsVplsLightTheObjectBeyondDirectLight) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  aim_at_the_virtual_box(scene);
  for (int level = 0; level < int(technique::dir_levels().size()); ++level) {
    SCOPED_TRACE(level);
    // The lamp's bounce alone (the environment VPLs take the ambient's occlusion away, below).
    DirAblation no_env;
    no_env.no_environment_vpls = true;
    const std::vector<FrameOutput> outs = run(scene, "dir", level, 3, true, no_env);
    ASSERT_EQ(outs.size(), 3u);
    bool diffuse_note = false;
    for (const std::string& k : outs.back().stats.skipped) {
      EXPECT_EQ(k.find("not built yet"), std::string::npos) << k;
      diffuse_note |= k.find("dir glossy VPLs: no glossy virtual material") != std::string::npos;
    }
    EXPECT_TRUE(diffuse_note) << "diffuse cubes: the glossy VPLs are skipped and said so";
    // Direct light without any bounce: baseline without the lamps' bounce off the objects that
    // its environment occlusion adds (shading/environment_occlusion.h lights_bounce).
    const std::vector<FrameOutput> base = run(scene, "baseline", technique::dir_levels()[size_t(level)].baseline_level, 3,
                                              false, {}, {{"env_occlusion_lights_bounce", 0}});
    ASSERT_EQ(base.size(), 3u);
    const double with_vpls = virtual_light(scene, outs.back()), direct = virtual_light(scene, base.back());
    // The camera looks down on the boxes' tops, which the floor's bounce (from below) hardly
    // reaches: light is added, not much (measured +0.6 %).
    EXPECT_GT(with_vpls, direct) << "the floor's bounce must add light to the boxes";
    // The red boxes' bounce onto the lit floor around them (VPL 2 of the paper's Fig. 6,
    // L_r D_v D_r E, only in L_rv): redder than direct light's there.
    const Box& box = scene.virtual_boxes[0];
    const int w = scene.intrinsics.width, h = scene.intrinsics.height;
    double red = 0.0, green = 0.0, env_change = 0.0;
    int n = 0;
    // The environment VPLs: the uniform sky the boxes hide from the floor around them (which
    // baseline's unshadowed SH ambient keeps) is taken away there.
    const std::vector<FrameOutput> with_env = run(scene, "dir", level, 3, false);
    ASSERT_EQ(with_env.size(), 3u);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const SurfaceHit hit = scene.trace(u, v, true);
        if (hit.kind != SurfaceKind::Floor || scene.blocked_by_virtual(hit.point) || scene.blocked_by_real(hit.point))
          continue;
        const glm::vec3 near = glm::clamp(hit.point, box.lo, box.hi);
        if (glm::length(glm::vec2(hit.point.x - near.x, hit.point.z - near.z)) > 0.2f) continue;
        const size_t o = (size_t(v) * w + u) * 4;
        red += lin(outs.back().image.data[o]) - lin(base.back().image.data[o]);
        for (int c = 0; c < 3; ++c) env_change += lin(with_env.back().image.data[o + c]) - lin(outs.back().image.data[o + c]);
        green += lin(outs.back().image.data[o + 1]) - lin(base.back().image.data[o + 1]);
        ++n;
      }
    ASSERT_GT(n, 0);
    EXPECT_GT(red / n, 0.002) << "the boxes' red bounce on the floor around them";
    EXPECT_GT(red, 2.0 * green) << "the bounce takes the boxes' colour (red 0.8, green 0.2)";
    std::printf("level %d: floor around the boxes, environment VPLs change it by %.5f (linear, mean of RGB)\n", level,
                env_change / (3.0 * n));
    if (technique::dir_levels()[size_t(level)].env_vpls == 0) {
      // No environment VPLs at this level: the environment's share is the direct-light block's
      // (its occlusion with or without the ablation), so the ablation changes nothing.
      EXPECT_NEAR(env_change / (3.0 * n), 0.0, 1e-6) << "no environment VPLs at this level";
    } else if (technique::dir_levels()[size_t(level)].shadowed_env < 0) {
      EXPECT_LT(env_change / (3.0 * n), -5e-4) << "the boxes shadow the environment's light on the floor around them";
    } else {
      // The fast levels' VPLs also take the regions baseline would shadow with maps (the
      // ablation keeps those maps): the VPLs' shadows stand in for the maps' (measured: fast
      // -0.0047, more regions shadowed; fastest +0.0010, the same four, a little less dark).
      EXPECT_LT(std::abs(env_change / (3.0 * n)), 0.01) << "the VPLs' shadows stand in for baseline's maps";
    }
    for (uint8_t c : outs.back().image.data) ASSERT_LE(c, 255);  // (a frame came back whole)
  }
}

// The reuse of unchanged inputs (gi/input_reuse.h): identical frames reuse the VPLs and ISMs and
// give the recomputed frame's output bit for bit; a depth frame 1.8 mm off everywhere (within the
// 2 mm tolerance) is reused too and stays within a few 8-bit levels of a runtime that
// recomputes it; 1 cm of depth or 5 cm of camera motion recompute. Validation on.
// Glossy cubes (metallic 1, roughness 0.4): glossy VPLs on (no skip note), and the floor's
// bounce lights the cubes beyond baseline's direct light. A metal's diffuse part is 0, so that
// light reaches them only through their specular BRDF (the glossy receiver; measured +2 %).
TEST(Dir, GlossyCubesGetGlossyVpls) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(0.9f), 1.0f, 0.4f);
  aim_at_the_virtual_box(scene);
  DirAblation no_env;
  no_env.no_environment_vpls = true;
  const std::vector<FrameOutput> outs = run(scene, "dir", 2, 3, true, no_env);
  ASSERT_EQ(outs.size(), 3u);
  for (const std::string& k : outs.back().stats.skipped) EXPECT_EQ(k.find("dir glossy VPLs"), std::string::npos) << k;
  const std::vector<FrameOutput> base = run(scene, "baseline", technique::dir_levels()[2].baseline_level, 3, false);
  ASSERT_EQ(base.size(), 3u);
  // The floor's bounce reaches the metal cubes through their specular BRDF (the diffuse part of
  // a metal is 0: without the glossy receiver they would get nothing from the VPLs).
  const double with_vpls = virtual_light(scene, outs.back()), direct = virtual_light(scene, base.back());
  std::printf("metal cubes: %.5f with glossy VPLs, %.5f direct only\n", with_vpls, direct);
  EXPECT_GT(with_vpls, direct * 1.005);
}

// The one-map ablation (DirAblation::one_shadow_map) in the lamps' direct light: where the
// virtual plate C2's shadow falls inside the real box's own (the paper's Fig. 5), one map holds
// only the nearer caster, the plate, so L_r loses the real shadow there and the composite darkens
// the camera's already dark shadow again: the double shadow. Two maps: the camera's value stays.
TEST(Dir, OneShadowMapDarkensTheRealShadowTwiceWhereAVirtualOneOverlapsIt) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  DirAblation one;
  one.one_shadow_map = true;
  const std::vector<FrameOutput> two_maps = run(scene, "dir", 2, 2, true);
  const std::vector<FrameOutput> one_map = run(scene, "dir", 2, 2, true, one);
  ASSERT_EQ(two_maps.size(), 2u);
  ASSERT_EQ(one_map.size(), 2u);
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  double both_two = 0.0, both_one = 0.0;
  int n = 0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const SurfaceHit hit = scene.trace(u, v, true);
      if (hit.kind == SurfaceKind::Virtual || hit.kind == SurfaceKind::None) continue;
      if (!scene.blocked_by_real(hit.point) || !scene.blocked_by_virtual(hit.point)) continue;
      const size_t o = (size_t(v) * w + u) * 4;
      for (int c = 0; c < 3; ++c) {
        both_two += lin(two_maps.back().image.data[o + c]);
        both_one += lin(one_map.back().image.data[o + c]);
      }
      ++n;
    }
  ASSERT_GT(n, 0) << "the scene has pixels in both shadows (C2 over the real box's shadow)";
  std::printf("both shadows: %.4f with two maps, %.4f with one (mean linear RGB, %d pixels)\n", both_two / (3.0 * n),
              both_one / (3.0 * n), n);
  EXPECT_LT(both_one, 0.8 * both_two) << "one map: the double shadow of Fig. 5";
}

TEST(Dir, VplsAndIsmsAreReusedOnlyWhileTheInputsStayWithinTolerance) {
  mrgi::testing::TempDir dir;
  check_reuse_within_tolerance(dir.str(), "dir", 3, "dir maps, VPLs and ISMs: reused");
}

// With bounce slots (medium) a still scene is not reused at once: the bounce light source adds a
// bounce each frame (kBounceGenerations frames), then the VPLs are reused. The first frame has
// no previous VPLs to bounce and says so; the fast level has no bounce pass and says so.
TEST(Dir, WithBounceSlotsStillFramesAreReusedOnceTheBounceSettled) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  aim_at_the_virtual_box(scene);
  DirAblation plain;  // the frames themselves, not the smoothing's convergence
  plain.no_temporal_smoothing = true;
  const std::vector<FrameOutput> outs = run(scene, "dir", 2, 6, true, plain);
  ASSERT_EQ(outs.size(), 6u);
  auto has = [](const FrameOutput& o, const std::string& note) {
    for (const std::string& k : o.stats.skipped)
      if (k.rfind(note, 0) == 0) return true;
    return false;
  };
  const bool reused[] = {false, false, false, false, true, true};
  for (size_t i = 0; i < outs.size(); ++i)
    EXPECT_EQ(has(outs[i], "dir maps, VPLs and ISMs: reused"), reused[i]) << "frame " << i;
  EXPECT_TRUE(has(outs[0], "dir bounce VPLs: no previous frame's VPLs"));
  EXPECT_FALSE(has(outs[1], "dir bounce VPLs"));
  EXPECT_TRUE(outs[5].image.data == outs[4].image.data) << "a reused frame differs from the one that made its VPLs";
  // Each generation adds the next bounce on top of the last: the change shrinks.
  auto change = [&](size_t a, size_t b) {
    double sum = 0.0;
    for (size_t k = 0; k < outs[a].image.data.size(); ++k) sum += std::abs(int(outs[a].image.data[k]) - int(outs[b].image.data[k]));
    return sum;
  };
  std::printf("dir medium, still frames: change 1-2 %.0f, 2-3 %.0f, 3-4 %.0f (sum of 8-bit levels)\n", change(1, 2), change(2, 3),
              change(3, 4));
  const std::vector<FrameOutput> fast = run(scene, "dir", 3, 2, false);
  ASSERT_EQ(fast.size(), 2u);
  EXPECT_TRUE(has(fast[1], "dir bounce VPLs: none at this level"));
}

// Temporal smoothing (shaders/dir/temporal.comp): on still frames (reused VPLs) it converges to
// the frame itself, so it adds no bias, and the first frame, with no history, says so. (Its
// damping of VPL flicker is measured on the suite's captures, where camera motion re-samples
// the VPLs: perf/tools/temporal_stability.py, perf/results/dir/; the synthetic scene's VPLs are
// the same from frame to frame.)
TEST(Dir, TemporalSmoothingKeepsStillFramesAndSaysWhenItHasNoHistory) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  aim_at_the_virtual_box(scene);
  DirAblation off;
  off.no_temporal_smoothing = true;
  const std::vector<FrameOutput> on = run(scene, "dir", 3, 8, true), plain = run(scene, "dir", 3, 8, false, off);
  ASSERT_EQ(on.size(), 8u);
  ASSERT_EQ(plain.size(), 8u);
  int worst = 0;
  for (size_t k = 0; k < on.back().image.data.size(); ++k)
    worst = std::max(worst, std::abs(int(on.back().image.data[k]) - int(plain.back().image.data[k])));
  std::printf("dir fast, still frames: smoothed and plain differ by at most %d / 255 after 8 frames\n", worst);
  EXPECT_LE(worst, 1) << "on still frames the smoothed light is the frame's own";
  auto has = [](const FrameOutput& o, const std::string& note) {
    for (const std::string& k : o.stats.skipped)
      if (k.rfind(note, 0) == 0) return true;
    return false;
  };
  EXPECT_TRUE(has(on.front(), "dir temporal smoothing: no history"));
  EXPECT_FALSE(has(on.back(), "dir temporal smoothing"));
  EXPECT_TRUE(has(plain.back(), "dir temporal smoothing: off"));
}

// A spot whose cone misses the virtual objects draws R^mu only (R^rho would be its copy) and
// says so in FrameStats::skipped.
TEST(Dir, ASpotMissingTheObjectsDrawsNoVirtualMap) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  // Straight down from (-1.2, 1.2, 0), a 10 degree cone: both virtual boxes lie 50+ degrees off.
  for (LightDesc* l : {&scene.lamp, &scene.scene.lights[0]}) {
    l->direction = glm::vec3(0.0f, -1.0f, 0.0f);
    l->inner_angle_deg = 8.0f;
    l->outer_angle_deg = 10.0f;
  }
  const std::vector<FrameOutput> outs = run(scene, "dir", 3, 2, true);
  ASSERT_EQ(outs.size(), 2u);
  bool note = false;  // on the first frame (the second reuses its maps)
  for (const std::string& k : outs.front().stats.skipped) note |= k.find("no virtual object in the lamp's cone") != std::string::npos;
  EXPECT_TRUE(note);
}

// Stress: 1,000 frames at the fast level for a lamp at 1e6, a point lamp inside the
// virtual object (no map can hold it: skipped and said, the frame still lit directly), a black
// object (its map covers texels but reflects nothing: no VPL from the virtual map) and a spot
// cone so narrow that its map is lit in a few texels (every VPL drawn from them). The depth
// alternates by 1 cm (beyond the reuse tolerance), so VPLs and ISMs are rebuilt every frame and
// nothing may accumulate: frames of the same input are equal bit for bit once the
// reconstruction's filter has settled (the last against the 100th from last), and the mean
// light of the last 20 frames is within 1 % of frames 40-59's.
const StressVariant kStress[] = {
    {"lamp_at_1e6", glm::vec3(0.8f, 0.2f, 0.2f), [](SyntheticScene& s) { s.scene.lights[0].intensity = 1e6f; }},
    {"point_lamp_inside_the_object", glm::vec3(0.8f, 0.2f, 0.2f),
     [](SyntheticScene& s) {
       s.scene.lights[0].type = LightType::Point;
       s.scene.lights[0].position = 0.5f * (s.virtual_boxes[0].lo + s.virtual_boxes[0].hi);
     }},
    {"black_object_no_virtual_vpls", glm::vec3(0.0f), [](SyntheticScene&) {}},
    {"narrow_cone_vpls_on_few_texels", glm::vec3(0.8f, 0.2f, 0.2f),
     [](SyntheticScene& s) {
       s.scene.lights[0].inner_angle_deg = 0.2f;
       s.scene.lights[0].outer_angle_deg = 0.3f;
     }},
};

class DirStress : public ::testing::TestWithParam<int> {};

TEST_P(DirStress, ThousandFramesStayFiniteAndDoNotGrow) {
  mrgi::testing::TempDir dir;
  StressOutcome o;
  run_stress(kStress[GetParam()], dir.str(), "dir", 3, "dir maps, VPLs and ISMs: reused", 1000, o);
  if (HasFatalFailure()) return;
  check_stress_outcome(o);
  EXPECT_EQ(o.inside_note, GetParam() == 1) << "the point lamp inside the object is said to be skipped";
}

INSTANTIATE_TEST_SUITE_P(Variants, DirStress, ::testing::Range(0, int(std::size(kStress))),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(kStress[info.param].name); });

// The same at medium, whose bounce light source feeds each frame's VPLs on the last frame's: 1,000
// generations of bounces must not grow (the estimator's expected flux is the surfaces' albedo
// times what reaches them, below 1 a bounce).
class DirStressMultiBounce : public ::testing::TestWithParam<int> {};

TEST_P(DirStressMultiBounce, ThousandFramesStayFiniteAndDoNotGrow) {
  mrgi::testing::TempDir dir;
  StressOutcome o;
  ASSERT_GT(technique::dir_levels()[2].bounce_vpls, 0u);
  run_stress(kStress[GetParam()], dir.str(), "dir", 2, "dir maps, VPLs and ISMs: reused", 1000, o);
  if (HasFatalFailure()) return;
  check_stress_outcome(o);
}

INSTANTIATE_TEST_SUITE_P(Variants, DirStressMultiBounce, ::testing::Values(0),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(kStress[info.param].name); });

}  // namespace
}  // namespace mrgi::test

// The environment VPLs take every region the direct-light block does not draw with a shadow
// map, wherever the light stage's shadowed regions lie in the cut (only compact, bright, distant
// ones are shadowed): no region both mapped and a VPL, none left with neither.
TEST(Dir, EnvironmentVplsTakeEveryRegionWithoutAShadowMap) {
  using mrgi::technique::environment_vpl_regions;
  uint32_t out[16];
  // Regions 0 and 5 of 8 shadowed, both with maps: the VPLs are 1-4, 6, 7.
  ASSERT_EQ(environment_vpl_regions(8, {0, 5}, 2, 16, out), 6u);
  EXPECT_EQ(std::vector<uint32_t>(out, out + 6), (std::vector<uint32_t>{1, 2, 3, 4, 6, 7}));
  // Only the first of them has a map at this level: 5 is a VPL again.
  ASSERT_EQ(environment_vpl_regions(8, {0, 5}, 1, 16, out), 7u);
  EXPECT_EQ(std::vector<uint32_t>(out, out + 7), (std::vector<uint32_t>{1, 2, 3, 4, 5, 6, 7}));
  // At most `most`, strongest first; none mapped: every region.
  ASSERT_EQ(environment_vpl_regions(8, {3}, 1, 3, out), 3u);
  EXPECT_EQ(std::vector<uint32_t>(out, out + 3), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(environment_vpl_regions(4, {}, 0, 16, out), 4u);
  EXPECT_EQ(environment_vpl_regions(0, {0, 1}, 2, 16, out), 0u);
  // More mapped than shadowed: the shadowed ones only.
  EXPECT_EQ(environment_vpl_regions(3, {1}, 4, 16, out), 2u);
}
