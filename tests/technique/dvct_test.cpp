// The dvct technique end to end on the synthetic scene (synthetic_scene.h) with Vulkan validation
// on (a message fails process()/flush()): every level runs, says what it leaves out, lights the
// virtual boxes and takes light away from the real floor where the boxes block the lamp (the
// shadow cones at the paper level, baseline's maps below it, and the delta light volume's
// negative light in the cones' bounce). Accuracy against path-traced references is the bench's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "stress_run.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

struct Light {
  double virtual_mean = 0.0, shadow_change = 0.0;
  int virtual_n = 0, shadow_n = 0;
};

// Mean linear light of the virtual pixels, and the mean change against the camera of the floor
// pixels a virtual box shadows (and the real box does not).
Light measure(const SyntheticScene& scene, const FrameOutput& out, const InputFrame& in) {
  Light l;
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const SurfaceHit hit = scene.trace(u, v, true);
      const size_t i = (size_t(v) * w + u) * 3, o = (size_t(v) * w + u) * 4;
      double y_out = 0.0, y_in = 0.0;
      for (int c = 0; c < 3; ++c) {
        y_out += lin(out.image.data[o + c]);
        y_in += lin(in.color.data[i + c]);
      }
      if (hit.kind == SurfaceKind::Virtual) {
        l.virtual_mean += y_out;
        ++l.virtual_n;
      } else if (hit.kind == SurfaceKind::Floor && scene.blocked_by_virtual(hit.point) && !scene.blocked_by_real(hit.point)) {
        l.shadow_change += y_out - y_in;
        ++l.shadow_n;
      }
    }
  if (l.virtual_n) l.virtual_mean /= l.virtual_n;
  if (l.shadow_n) l.shadow_change /= l.shadow_n;
  return l;
}

// Mean linear gain of `a` over `b` in red and green on the floor within 10 cm of the virtual
// boxes (x red, y green, z pixel count).
glm::dvec3 floor_gain_near_boxes(const SyntheticScene& scene, const FrameOutput& a, const FrameOutput& b) {
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  glm::dvec3 g(0.0);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const SurfaceHit hit = scene.trace(u, v, true);
      if (hit.kind != SurfaceKind::Floor) continue;
      float nearest = 1e9f;
      for (const Box& box : scene.virtual_boxes)
        nearest = std::min(nearest, glm::length(glm::max(glm::max(box.lo - hit.point, hit.point - box.hi), glm::vec3(0.0f))));
      if (nearest > 0.1f) continue;
      const size_t o = (size_t(v) * w + u) * 4;
      g.x += lin(a.image.data[o]) - lin(b.image.data[o]);
      g.y += lin(a.image.data[o + 1]) - lin(b.image.data[o + 1]);
      g.z += 1.0;
    }
  if (g.z > 0.0) {
    g.x /= g.z;
    g.y /= g.z;
  }
  return g;
}

bool has_note(const FrameOutput& o, const std::string& prefix) {
  for (const std::string& k : o.stats.skipped)
    if (k.rfind(prefix, 0) == 0) return true;
  return false;
}

TEST(Dvct, EveryLevelLightsTheObjectAndDarkensTheFloorWithValidationOn) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  for (int level = 0; level < 5; ++level) {
    SCOPED_TRACE(level);
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = "dvct";
    s.level = level;
    const std::vector<FrameOutput> outs = run_synthetic_frames(scene, s, 3);
    ASSERT_EQ(outs.size(), 3u);
    const Light l = measure(scene, outs.back(), scene.frame(2));
    ASSERT_GT(l.virtual_n, 0);
    ASSERT_GT(l.shadow_n, 0);
    EXPECT_GT(l.virtual_mean, 0.05);
    EXPECT_LT(l.shadow_change, -0.01) << "the floor in the boxes' shadow must lose light";
    // The diffuse boxes need no specular cone: said, at every level (why differs).
    EXPECT_TRUE(has_note(outs.back(), "dvct specular cone")) << "level " << level;
  }
}

// The cones' light, not only the direct light: against baseline's matching level without any bounce (the same
// shadow maps, so the difference is the cones'), the floor within 10 cm of the red boxes gains
// more red than green: the boxes' bounce, the delta light volume's positive light.
TEST(Dvct, TheBoxesBounceRedLightOntoTheFloorBeyondDirectLight) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  auto run = [&](const char* technique, int level, const std::vector<KnobSetting>& knobs) {
    RuntimeSettings s;
    s.technique = technique;
    s.level = level;
    s.knobs = knobs;
    return run_synthetic_frames(scene, s, 3);
  };
  // dvct high against baseline high's maps without the lamps' bounce off the objects that its
  // environment occlusion adds (direct light only).
  const std::vector<FrameOutput> dvct = run("dvct", 1, {}), base = run("baseline", 0, {{"env_occlusion_lights_bounce", 0}});
  ASSERT_EQ(dvct.size(), 3u);
  ASSERT_EQ(base.size(), 3u);
  const glm::dvec3 g = floor_gain_near_boxes(scene, dvct.back(), base.back());
  ASSERT_GT(g.z, 0.0);
  std::printf("floor within 10 cm of the boxes (%d px): red %+.4f, green %+.4f over baseline\n", int(g.z), g.x, g.y);
  EXPECT_GT(g.x, g.y + 0.002) << "the red boxes' bounce";
}

// The volumes' reuse (dvct.h "Skips"): identical frames reuse them and give the recomputed
// frame's output bit for bit; 1.8 mm of depth change is reused within 4/255 of a recomputed
// frame; 1 cm of depth or 5 cm of camera motion recompute. Validation on.
TEST(Dvct, VolumesAreReusedOnlyWhileTheInputsStayWithinTolerance) {
  mrgi::testing::TempDir dir;
  check_reuse_within_tolerance(dir.str(), "dvct", 3, "dvct voxelisation and injection: reused");
}

// The object visibility volume is kept while the objects stay put (dvct.h "Skips") and made
// again when one moves: frame 0 voxelises it, frame 1 (same poses) reuses it and renders what a
// runtime voxelising it again renders, bit for bit; frame 2, after set_object_placement, makes
// it again. One frame in flight, validation on.
TEST(Dvct, ObjectVisibilityIsKeptUntilAnObjectMoves) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  RuntimeSettings s;
  s.technique = "dvct";
  s.level = 3;
  s.device.validate = true;
  s.frames_in_flight = 1;
  auto rt = create_runtime(s, scene.cameras(), scene.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  std::vector<FrameOutput> outs;
  auto step = [&](const InputFrame& f) {
    auto o = (*rt)->process(f);
    ASSERT_TRUE(o.ok()) << o.error().message;
    for (auto& x : *o) outs.push_back(std::move(x));
  };
  // Depth 1 cm off on frame 1 so the light volumes are made again (beyond the reuse tolerance):
  // only the object volume is kept.
  InputFrame shifted = scene.frame(1);
  for (uint16_t& d : shifted.depth.data)
    if (d != 0) d = uint16_t(d + uint16_t(scene.depth_scale / 100.0));
  step(scene.frame(0));
  step(shifted);
  Placement moved = scene.scene.virtual_objects[0].placement;
  moved.position.x += 0.1f;
  ASSERT_TRUE((*rt)->set_object_placement(0, moved).ok());
  step(scene.frame(2));
  auto rest = (*rt)->flush();
  ASSERT_TRUE(rest.ok()) << rest.error().message;
  for (auto& x : *rest) outs.push_back(std::move(x));
  ASSERT_EQ(outs.size(), 3u);
  const std::string note = "dvct object visibility: reused";
  EXPECT_FALSE(has_note(outs[0], note));
  EXPECT_TRUE(has_note(outs[1], note));
  EXPECT_FALSE(has_note(outs[2], note)) << "an object moved: voxelised again";
  // A second runtime voxelises it again on frame 1: its object is moved away and back before it
  // (each move bumps the scene's revision, the geometry ends where it was): the same output
  // bit for bit.
  std::vector<FrameOutput> again;
  auto rt2 = create_runtime(s, scene.cameras(), scene.scene);
  ASSERT_TRUE(rt2.ok()) << rt2.error().message;
  for (int k = 0; k < 2; ++k) {
    if (k == 1) {
      ASSERT_TRUE((*rt2)->set_object_placement(0, moved).ok());
      ASSERT_TRUE((*rt2)->set_object_placement(0, scene.scene.virtual_objects[0].placement).ok());
    }
    auto o = (*rt2)->process(k == 0 ? scene.frame(0) : shifted);
    ASSERT_TRUE(o.ok()) << o.error().message;
    for (auto& x : *o) again.push_back(std::move(x));
  }
  auto rest2 = (*rt2)->flush();
  ASSERT_TRUE(rest2.ok());
  for (auto& x : *rest2) again.push_back(std::move(x));
  ASSERT_EQ(again.size(), 2u);
  EXPECT_FALSE(has_note(again[1], note));
  EXPECT_TRUE(again[1].image.data == outs[1].image.data) << "the kept volume renders as one voxelised again";
}

// A glossy (metal, roughness 0.2) box gets its specular cone: no "specular cone" note at a level
// that has one, and its light differs from the same level with the cone turned off by knob.
TEST(Dvct, GlossyBoxesGetTheSpecularCone) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(0.9f), 1.0f, 0.2f);
  auto run = [&](bool specular) {
    RuntimeSettings s;
    s.technique = "dvct";
    s.level = 2;
    s.device.validate = true;
    if (!specular) s.knobs = {{"specular_cone", 0}};
    return run_synthetic_frames(scene, s, 3);
  };
  const std::vector<FrameOutput> with = run(true), without = run(false);
  ASSERT_EQ(with.size(), 3u);
  ASSERT_EQ(without.size(), 3u);
  EXPECT_FALSE(has_note(with.back(), "dvct specular cone"));
  EXPECT_TRUE(has_note(without.back(), "dvct specular cone"));
  const Light a = measure(scene, with.back(), scene.frame(2)), b = measure(scene, without.back(), scene.frame(2));
  std::printf("metal boxes: %.5f with the specular cone, %.5f without\n", a.virtual_mean, b.virtual_mean);
  EXPECT_GT(std::abs(a.virtual_mean - b.virtual_mean), 1e-3);
}

// `scene` with one glossy real region (roughness 0.1) over [lo, hi].
SyntheticScene with_glossy_region(const SyntheticScene& scene, const glm::vec3& lo, const glm::vec3& hi) {
  SyntheticScene out = scene;
  RealMaterialRegion r;
  r.min = lo;
  r.max = hi;
  r.roughness = 0.1f;
  out.scene.real_materials = {r};
  return out;
}

// Three frames at the medium level (the specular cone), validation on.
std::vector<FrameOutput> run_medium(const SyntheticScene& scene) {
  RuntimeSettings s;
  s.technique = "dvct";
  s.level = 2;
  s.device.validate = true;
  return run_synthetic_frames(scene, s, 3);
}

// A real material region (scene.json real_materials) makes the real floor glossy: the specular
// cone then runs on its pixels (no "specular cone" note although the boxes are diffuse) and the
// floor near the red boxes reflects them: it gains red over the same scene without the region.
TEST(Dvct, AGlossyRealRegionReflectsTheBoxes) {
  mrgi::testing::TempDir dir;
  const SyntheticScene plain = SyntheticScene::create(dir.str());
  const SyntheticScene glossy = with_glossy_region(plain, glm::vec3(-5.0f, -0.02f, -5.0f), glm::vec3(5.0f, 0.02f, 5.0f));
  const std::vector<FrameOutput> with = run_medium(glossy), without = run_medium(plain);
  ASSERT_EQ(with.size(), 3u);
  ASSERT_EQ(without.size(), 3u);
  EXPECT_FALSE(has_note(with.back(), "dvct specular cone"));
  EXPECT_TRUE(has_note(without.back(), "dvct specular cone"));
  const glm::dvec3 g = floor_gain_near_boxes(plain, with.back(), without.back());
  ASSERT_GT(g.z, 0.0);
  std::printf("glossy floor within 10 cm of the boxes (%d px): red %+.4f, green %+.4f over a diffuse one\n", int(g.z),
              g.x, g.y);
  EXPECT_GT(g.x, g.y + 0.001) << "the red boxes' reflection";
}

// Under an environment alone (no lamp: no reflective shadow map puts light on the objects), a
// glossy floor reflects the objects with their own light (DvctLevel::object_light: their
// emission and ambient injected into the volume the specular cone reads), not as black: the
// floor beside orange-glowing boxes gains red over green, and more than without that volume,
// where the boxes hide the environment's reflection and give nothing back.
TEST(Dvct, AGlossyFloorUnderAnEnvironmentReflectsTheObjectsWithTheirOwnLight) {
  mrgi::testing::TempDir dir;
  SyntheticScene glowing = SyntheticScene::create(dir.str(), glm::vec3(0.6f, 0.25f, 0.0f));
  glowing.scene.lights.clear();
  const SyntheticScene glossy = with_glossy_region(glowing, glm::vec3(-5.0f, -0.02f, -5.0f), glm::vec3(5.0f, 0.02f, 5.0f));
  auto run = [&](double object_light) {
    RuntimeSettings s;
    s.technique = "dvct";
    s.level = 2;
    s.device.validate = true;
    s.knobs = {{"object_light", object_light}};
    return run_synthetic_frames(glossy, s, 3);
  };
  const std::vector<FrameOutput> with = run(1.0), without = run(0.0);
  ASSERT_EQ(with.size(), 3u);
  ASSERT_EQ(without.size(), 3u);
  EXPECT_FALSE(has_note(with.back(), "dvct specular cone"));
  const glm::dvec3 g = floor_gain_near_boxes(glowing, with.back(), without.back());
  ASSERT_GT(g.z, 0.0);
  std::printf("glossy floor within 10 cm of glowing boxes (%d px), object light on over off: red %+.4f, green %+.4f\n",
              int(g.z), g.x, g.y);
  EXPECT_GT(g.x, 0.002) << "the boxes' glow in the floor";
  EXPECT_GT(g.x, g.y + 0.001) << "in the boxes' colour";
}

// The specular-cone skip (dvct.h "Skips"): a glossy real region outside the camera's view
// compiles the cone out ("no glossy material in view") and the frame is the one the same scene
// without the region gives, bit for bit (no glossy pixel: nothing the cone would have added).
TEST(Dvct, AGlossyRegionOutOfViewTracesNoSpecularCone) {
  mrgi::testing::TempDir dir;
  const SyntheticScene plain = SyntheticScene::create(dir.str());
  const SyntheticScene away = with_glossy_region(plain, glm::vec3(49.0f, -0.02f, -1.0f), glm::vec3(51.0f, 0.02f, 1.0f));
  const std::vector<FrameOutput> with = run_medium(away), without = run_medium(plain);
  ASSERT_EQ(with.size(), 3u);
  ASSERT_EQ(without.size(), 3u);
  EXPECT_TRUE(has_note(with.back(), "dvct specular cone: no glossy material in view"));
  EXPECT_TRUE(with.back().image.data == without.back().image.data);
}

// Stress: 1,000 frames at the fast level (16^3; the glossy variants with its specular
// cone turned on by knob), each rebuilding its volumes (the depth alternates by 1 cm, beyond the
// reuse tolerance): an object larger than the scene (the region, twice its size, holds the whole
// real scene coarsely), an empty volume (one box 1 m above the floor, in view, with no real
// surface in its region), a mirror-smooth metal object (roughness 0: the narrowest specular cone) and a
// fully rough one (roughness 1: at the limit, no specular cone), and a lamp at 1e6. Nothing may accumulate: frames of the same input are equal bit for
// bit once the reconstruction's filter settled, and the mean light of the last frames is within
// 1 % of frames 40-59's.
const StressVariant kStress[] = {
    {"object_larger_than_the_scene", glm::vec3(0.8f, 0.2f, 0.2f),
     [](SyntheticScene& s) { s.scene.virtual_objects[0].placement.scale *= 20.0f; }},
    {"empty_volume", glm::vec3(0.8f, 0.2f, 0.2f),
     [](SyntheticScene& s) {
       s.scene.virtual_objects.resize(1);  // the 0.4 m box alone, 1 m up: its region spans y 0.8-1.6 m
       s.scene.virtual_objects[0].placement.position.y = 1.0f;
     }},
    {"roughness_0", glm::vec3(0.9f), [](SyntheticScene&) {}, 1.0f, 0.0f, "specular_cone", 1.0},
    {"roughness_1", glm::vec3(0.9f), [](SyntheticScene&) {}, 1.0f, 1.0f, "specular_cone", 1.0},
    {"lamp_at_1e6", glm::vec3(0.8f, 0.2f, 0.2f), [](SyntheticScene& s) { s.scene.lights[0].intensity = 1e6f; }},
};

class DvctStress : public ::testing::TestWithParam<int> {};

TEST_P(DvctStress, ThousandFramesStayFiniteAndDoNotGrow) {
  mrgi::testing::TempDir dir;
  StressOutcome o;
  run_stress(kStress[GetParam()], dir.str(), "dvct", 3, "dvct voxelisation and injection: reused", 1000, o);
  if (HasFatalFailure()) return;
  check_stress_outcome(o);
}

INSTANTIATE_TEST_SUITE_P(Variants, DvctStress, ::testing::Range(0, int(std::size(kStress))),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(kStress[info.param].name); });

}  // namespace
}  // namespace mrgi::test
