// The specular stage (runtime/src/specular/) end to end on the synthetic scene (synthetic_scene.h:
// a camera 2 m above the floor looking down, a real spot lamp, a uniform real environment), with
// Vulkan validation on: a mirror shows the environment times its reflectance, glass shows the
// camera's floor through it, and a scene without such a material runs none of the stage's passes
// and gives the same frames bit for bit; the fast level splats photons traced frames before with
// the energy of the level that traces them all every frame. Accuracy against path-traced
// references is the bench's.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/research.h"
#include "mrgi/image.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

// Linear colour of pixel (u, v) of an RGBA8 output or RGB8 input image.
glm::vec3 out_px(const FrameOutput& o, int u, int v) {
  const size_t i = (size_t(v) * size_t(o.image.width) + size_t(u)) * 4;
  return {lin(o.image.data[i]), lin(o.image.data[i + 1]), lin(o.image.data[i + 2])};
}
glm::vec3 in_px(const InputFrame& f, int u, int v) {
  const size_t i = (size_t(v) * size_t(f.color.width) + size_t(u)) * 3;
  return {lin(f.color.data[i]), lin(f.color.data[i + 1]), lin(f.color.data[i + 2])};
}

// The pixels whose camera ray meets the first virtual box's top face at least `margin` metres
// inside its edges (its centre, where nothing bends the rays sideways).
std::vector<glm::ivec2> top_centre_pixels(const SyntheticScene& s, float margin) {
  std::vector<glm::ivec2> px;
  const Box& b = s.virtual_boxes[0];
  for (int v = 0; v < s.intrinsics.height; ++v)
    for (int u = 0; u < s.intrinsics.width; ++u) {
      const SurfaceHit h = s.trace(u, v, true);
      if (h.kind != SurfaceKind::Virtual || h.virtual_index != 0 || h.normal.y < 0.9f) continue;
      if (h.point.x < b.lo.x + margin || h.point.x > b.hi.x - margin || h.point.z < b.lo.z + margin ||
          h.point.z > b.hi.z - margin)
        continue;
      px.push_back({u, v});
    }
  return px;
}

RuntimeSettings settings_for(const char* technique, int level) {
  RuntimeSettings s;
  s.device.validate = true;
  s.technique = technique;
  s.level = level;
  return s;
}

// Three frames of `s` with dir at level 1, with the paper's method (first) and with one of
// SpecularAblation's flags set (second).
using Frames = std::vector<FrameOutput>;
std::pair<Frames, Frames> run_with_and_without(const SyntheticScene& s, bool SpecularAblation::*flag) {
  RuntimeSettings on = settings_for("dir", 1);
  RuntimeSettings off = on;
  auto research = std::make_shared<ResearchSettings>();
  research->specular.*flag = true;
  off.research = research;
  return {run_synthetic_frames(s, on, 3), run_synthetic_frames(s, off, 3)};
}

bool has_pass(const FrameOutput& o, const std::string& prefix) {
  for (const PassTiming& p : o.stats.passes)
    if (p.name.rfind(prefix, 0) == 0) return true;
  return false;
}

TEST(Specular, AMirrorShowsTheEnvironmentTimesItsReflectance) {
  // Looking straight down at a mirror's top face, the reflected ray goes straight up into the
  // uniform environment: the pixel is F0 x L_env x exposure (metal: F0 = its base colour).
  mrgi::testing::TempDir dir;
  const glm::vec3 base(0.9f, 0.6f, 0.3f);
  const SyntheticScene s = SyntheticScene::create(dir.str(), glm::vec3(0.0f), base, 1.0f, 0.0f);
  const auto px = top_centre_pixels(s, 0.04f);
  ASSERT_GT(px.size(), 4u);
  for (const char* technique : {"baseline", "dir"}) {
    const auto outs = run_synthetic_frames(s, settings_for(technique, 1), 3);
    ASSERT_EQ(outs.size(), 3u);
    EXPECT_TRUE(has_pass(outs.back(), "specular trace")) << technique;
    glm::vec3 mean(0.0f);
    for (const glm::ivec2& p : px) mean += out_px(outs.back(), p.x, p.y);
    mean /= float(px.size());
    const glm::vec3 expected = base * s.ambient * float(s.exposure);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(mean[c], expected[c], 0.1f * expected[c] + 2e-3f) << technique << " channel " << c;
  }
}

TEST(Specular, GlassShowsTheCamerasFloorThroughIt) {
  // A clear glass box on the floor seen from above: the refracted rays cross its parallel top
  // and bottom faces and meet the floor under it, which the camera sees (the box is virtual):
  // the pixel is the camera's floor colour there times the two interfaces' transmission and the
  // differential change of the floor's light (the box's shadow in the technique's maps, with the
  // caustic through the box in it), plus 4 % of reflected environment. The technique's diffuse
  // shading of the same box (the stage off) is white, far from it.
  mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(1.0f), 0.0f, 0.0f, 1.0f);
  const auto px = top_centre_pixels(s, 0.05f);
  ASSERT_GT(px.size(), 4u);
  const auto [a, b] = run_with_and_without(s, &SpecularAblation::off);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  const InputFrame in = s.frame(2);
  double ratio = 0.0, grey = 0.0, diffuse = 0.0;
  for (const glm::ivec2& p : px) {
    const glm::vec3 o = out_px(a.back(), p.x, p.y), c = in_px(in, p.x, p.y);
    ratio += (o.x + o.y + o.z) / std::max(1e-4f, c.x + c.y + c.z);
    grey += std::max(std::abs(o.x - o.y), std::abs(o.y - o.z)) / std::max(1e-4f, o.y);
    const glm::vec3 d = out_px(b.back(), p.x, p.y);
    diffuse += (d.x + d.y + d.z) / std::max(1e-4f, c.x + c.y + c.z);
  }
  ratio /= double(px.size());
  grey /= double(px.size());
  diffuse /= double(px.size());
  // The floor is grey in the camera: so is what the glass shows.
  EXPECT_LT(grey, 0.05);
  // The floor under the box is in its shadow in the technique's maps (glass is an opaque caster
  // there) and gets the lamp's light back as the caustic through the box: about the camera's
  // light, (1 - 0.04)^2 of it seen through the box, more where the light through the top and
  // through the lamp-facing side land together (the light through glass has no more than the
  // lamp's flux the box intercepts: GlassFocuses... below); without the caustic it would be the
  // ambient share alone.
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 1.3);
  EXPECT_GT(std::abs(diffuse - ratio), 0.2) << "the stage changed nothing";
  EXPECT_FALSE(has_pass(b.back(), "specular"));
}

// The light the caustics add to the floor the camera sees (W) and their mean gain on the floor
// in the glass's shadow near the first box, frame `with` against frame `without`.
struct CausticGain {
  double added_w = 0.0, shadow_gain = 0.0;
  int shadow_n = 0;
};
CausticGain caustic_gain(const SyntheticScene& s, const FrameOutput& with, const FrameOutput& without) {
  CausticGain g;
  const Box& box = s.virtual_boxes[0];
  const glm::vec3 c = 0.5f * (box.lo + box.hi);
  const double pixel_m = 2.0 / s.intrinsics.fx;  // the floor is 2 m below the camera
  for (int v = 0; v < s.intrinsics.height; ++v)
    for (int u = 0; u < s.intrinsics.width; ++u) {
      const SurfaceHit h = s.trace(u, v, true);
      if (h.kind != SurfaceKind::Floor) continue;
      const glm::vec3 d = out_px(with, u, v) - out_px(without, u, v);
      const double change = double(d.x + d.y + d.z) / 3.0;  // radiance x exposure (1)
      g.added_w += std::max(change, 0.0) * 3.14159265 / s.floor_albedo * pixel_m * pixel_m;
      if (s.blocked_by_virtual(h.point) && !s.blocked_by_real(h.point) && glm::distance(h.point, glm::vec3(c.x, 0.0f, c.z)) < 0.5f) {
        g.shadow_gain += change;
        ++g.shadow_n;
      }
    }
  return g;
}

// The boxes subtend at most pi r^2 / d^2 of the lamp (bounding spheres): 0.36 sr x 4 W/sr.
double intercepted_w(const SyntheticScene& s) {
  double w = 0.0;
  for (const Box& g : s.virtual_boxes) {
    const double r = 0.5 * glm::length(g.hi - g.lo), dist = glm::distance(0.5f * (g.lo + g.hi), s.lamp.position);
    w += 3.14159265 * r * r / (dist * dist) * s.lamp.intensity;
  }
  return w;
}

TEST(Specular, GlassFocusesTheSpotLampIntoItsShadowWithNoMoreThanItIntercepts) {
  // The spot lamp through the clear glass boxes: their caustics land on the floor they shadow
  // (the technique's maps hold glass as an opaque caster, so without caustics that floor gets
  // the ambient alone), and all the light the caustics add to the floor the camera sees is no
  // more than the lamp's flux the boxes intercept.
  mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(1.0f), 0.0f, 0.0f, 1.0f);
  const auto [a, b] = run_with_and_without(s, &SpecularAblation::no_caustics);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_TRUE(has_pass(a.back(), "specular caustic splat"));
  EXPECT_FALSE(has_pass(b.back(), "specular caustic splat"));
  const CausticGain g = caustic_gain(s, a.back(), b.back());
  ASSERT_GT(g.shadow_n, 4);
  // The floor's direct light there is about 0.1 (4 W/sr at 2 m, 53 degrees off the normal,
  // albedo 0.6): the light through the glass gives a part of it back on the shadow's visible
  // part (the rest lands under the box).
  EXPECT_GT(g.shadow_gain / g.shadow_n, 0.005) << "no caustic in the glass's shadow";
  EXPECT_GT(g.added_w, 0.0);
  EXPECT_LT(g.added_w, intercepted_w(s)) << "the caustics add more light than the glass intercepts";
}

TEST(Specular, TheFastLevelReadsReceiverMapsDrawnFramesAgoWithTheSameEnergy) {
  // dir's fast level (SpecularLevel "fast": 128^2 photon maps, a quarter of the glass-reflected
  // photons with four times the flux each, traced every sixteenth frame while nothing moves,
  // into 512^2 receiver maps): the photons are traced and drawn into the receiver maps on the
  // first frame, and the next frames' shading reads the maps (no pass of the stage's on them, no
  // splat into the camera's buffer) and says so; every frame's caustic holds about the energy of
  // level 1's, which traces and splats all of them every frame, and no more than the glass
  // intercepts. At this test's 32 x 24 internal pixels (10 cm on the floor) the maps' 1 cm texels
  // are read at their coarsest level: the pixel's caustic, not a point of it.
  mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(1.0f), 0.0f, 0.0f, 1.0f);
  RuntimeSettings fast = settings_for("dir", 3);
  RuntimeSettings fast_off = fast;
  auto no_caustics = std::make_shared<ResearchSettings>();
  no_caustics->specular.no_caustics = true;
  fast_off.research = no_caustics;
  const Frames a = run_synthetic_frames(s, fast, 4), b = run_synthetic_frames(s, fast_off, 4);
  const auto [ref_on, ref_off] = run_with_and_without(s, &SpecularAblation::no_caustics);
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  EXPECT_TRUE(has_pass(a[0], "specular photons 0"));
  EXPECT_TRUE(has_pass(a[0], "specular caustic receivers 0"));
  EXPECT_TRUE(has_pass(a[0], "specular caustic receiver mip 0.1"));
  const double reference_w = caustic_gain(s, ref_on.back(), ref_off.back()).added_w;
  ASSERT_GT(reference_w, 0.0);
  EXPECT_TRUE(has_pass(ref_on.back(), "specular caustic splat 0")) << "level 1 splats into the camera's buffer";
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_FALSE(has_pass(a[i], "specular caustic splat")) << "frame " << i;
    if (i == 0) continue;
    EXPECT_FALSE(has_pass(a[i], "specular photons 0")) << "frame " << i;
    EXPECT_FALSE(has_pass(a[i], "specular caustic receivers 0")) << "frame " << i;
    bool said = false;
    for (const std::string& k : a[i].stats.skipped) said = said || k.rfind("specular photons: traced", 0) == 0;
    EXPECT_TRUE(said) << "frame " << i;
    const CausticGain g = caustic_gain(s, a[i], b[i]);
    EXPECT_GT(g.added_w, 0.7 * reference_w) << "frame " << i;
    EXPECT_LT(g.added_w, 1.3 * reference_w) << "frame " << i;
    EXPECT_LT(g.added_w, intercepted_w(s)) << "frame " << i;
    EXPECT_GT(g.shadow_gain / g.shadow_n, 0.005) << "frame " << i << ": no caustic in the glass's shadow";
  }
}

TEST(Specular, ASceneWithoutSpecularMaterialRunsNoneOfItsPassesAndIsUnchanged) {
  mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  const auto [a, b] = run_with_and_without(s, &SpecularAblation::off);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_FALSE(has_pass(a[i], "specular")) << "frame " << i;
    EXPECT_EQ(a[i].image.data, b[i].image.data) << "frame " << i;
  }
}

TEST(Specular, AMirrorOutOfViewIsSkippedAndSaysSo) {
  mrgi::testing::TempDir dir;
  SyntheticScene s = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(0.9f), 1.0f, 0.0f);
  for (VirtualObjectDesc& o : s.scene.virtual_objects) o.placement.position.x += 30.0f;  // far outside the view
  const auto outs = run_synthetic_frames(s, settings_for("baseline", 1), 2);
  ASSERT_EQ(outs.size(), 2u);
  EXPECT_FALSE(has_pass(outs.back(), "specular"));
  bool said = false;
  for (const std::string& k : outs.back().stats.skipped) said = said || k.rfind("specular: no reflective or refractive object in view", 0) == 0;
  // Nothing virtual in view at all: the frame is the camera's and says that instead.
  for (const std::string& k : outs.back().stats.skipped) said = said || k.rfind("technique: no virtual object", 0) == 0;
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace mrgi::test
