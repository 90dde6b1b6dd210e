// The baseline technique end to end on the synthetic scene (synthetic_scene.h), with Vulkan
// validation on: any validation message makes process()/flush() fail, so every test also
// checks that.
//
// TODO(golden): compare against the path-traced reference capture (tools/reference) once the
// lead's reference generator writes one; not faked here.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

RuntimeSettings settings_for(int level, bool lights_bounce = false) {
  RuntimeSettings s;
  s.device.validate = true;
  s.technique = "baseline";
  s.level = level;
  s.knobs = {{"env_occlusion_lights_bounce", lights_bounce ? 1.0 : 0.0}};
  return s;
}

// Runs `frames` frames and returns every output (in order).
std::vector<FrameOutput> run(Runtime& rt, const std::vector<InputFrame>& frames) {
  std::vector<FrameOutput> all;
  for (const InputFrame& f : frames) {
    auto out = rt.process(f);
    EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
    if (!out.ok()) return all;
    for (auto& o : *out) all.push_back(std::move(o));
  }
  auto rest = rt.flush();
  EXPECT_TRUE(rest.ok()) << (rest.ok() ? "" : rest.error().message);
  if (rest.ok())
    for (auto& o : *rest) all.push_back(std::move(o));
  return all;
}

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

enum class Expect { Skip, Unchanged, Darker };

struct Classified {
  std::vector<Expect> expect;   // per pixel
  std::vector<bool> both;       // real shadow and virtual shadow together (DIR Fig. 5 case)
};

// Per pixel of the real scene: what the baseline must do there. A pixel is only tested when
// every pixel within `margin` has the same class (shadow edges, PCF and lower resolutions blur).
Classified classify(const SyntheticScene& s, int margin) {
  const int w = s.intrinsics.width, h = s.intrinsics.height;
  std::vector<int> cls(size_t(w) * h, -1);
  std::vector<bool> both(size_t(w) * h, false);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const SurfaceHit real = s.trace(u, v, false);
      const SurfaceHit seen = s.trace(u, v, true);
      if (seen.kind == SurfaceKind::Virtual || real.kind == SurfaceKind::None) continue;
      const glm::vec3 p = real.point + real.normal * 1e-4f;
      if (s.direct(p, real.normal) < 0.05f) continue;  // outside the cone or facing away
      const bool vshadow = s.blocked_by_virtual(p);
      const bool rtop = s.blocked_by_real_top(p);
      const bool rany = s.blocked_by_real(p);
      int c = -1;
      if (!vshadow) c = 0;                      // nothing virtual in the way: unchanged
      else if (rtop && rany) c = 2;             // already in the real shadow: unchanged
      else if (!rany) c = 1;                    // virtual shadow only: darker
      cls[size_t(v) * w + u] = c;
      both[size_t(v) * w + u] = c == 2;
    }
  }
  Classified out;
  out.expect.assign(cls.size(), Expect::Skip);
  out.both = both;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int c = cls[size_t(v) * w + u];
      if (c < 0) continue;
      bool uniform = true;
      for (int dv = -margin; dv <= margin && uniform; ++dv)
        for (int du = -margin; du <= margin && uniform; ++du) {
          const int x = u + du, y = v + dv;
          if (x < 0 || y < 0 || x >= w || y >= h || cls[size_t(y) * w + x] != c) uniform = false;
        }
      if (!uniform) continue;
      out.expect[size_t(v) * w + u] = c == 1 ? Expect::Darker : Expect::Unchanged;
      if (c != 2) out.both[size_t(v) * w + u] = false;
    }
  }
  return out;
}

class BaselineTest : public ::testing::Test {
 protected:
  void SetUp() override { scene_ = SyntheticScene::create(dir_.str()); }
  mrgi::testing::TempDir dir_;
  SyntheticScene scene_;
};

TEST_F(BaselineTest, EveryLevelShadowsOnlyWhereAVirtualObjectBlocksTheLamp) {
  auto names = technique_levels("baseline");
  ASSERT_TRUE(names.ok());
  ASSERT_GE(names->size(), 4u);
  const InputFrame input = scene_.frame(0);
  for (int level = 0; level < int(names->size()); ++level) {
    SCOPED_TRACE("level " + std::to_string(level) + " " + (*names)[size_t(level)]);
    // The shadows alone: the lamp's bounce off the red boxes, which reddens the floor beside
    // them, is off here (tested below).
    auto rt = create_runtime(settings_for(level, false), scene_.cameras(), scene_.scene);
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    const auto outs = run(**rt, {input, scene_.frame(1)});
    ASSERT_EQ(outs.size(), 2u);
    const FrameOutput& out = outs.back();
    EXPECT_EQ(out.stats.level, level);
    ASSERT_EQ(out.image.width, 64);
    ASSERT_EQ(out.image.height, 48);
    // Lower levels render at 3/4 and 1/2 resolution: a wider band around every edge.
    const int margin = level < 2 ? 2 : (level == 2 ? 3 : 4);
    const Classified cls = classify(scene_, margin);
    // At half resolution the two solutions are upsampled bilinearly before their ratio is taken,
    // which blends a 9-pixel-wide region with its neighbours: a wider tolerance there.
    const int tolerance = level < 3 ? 3 : 8;
    int darker = 0, unchanged = 0, both = 0;
    for (size_t i = 0; i < cls.expect.size(); ++i) {
      const uint8_t* o = &out.image.data[i * 4];
      const uint8_t* c = &input.color.data[i * 3];
      ASSERT_EQ(o[3], 255);
      if (cls.expect[i] == Expect::Unchanged) {
        ++unchanged;
        if (cls.both[i]) ++both;
        EXPECT_NEAR(int(o[0]), int(c[0]), tolerance) << "pixel " << i % 64 << "," << i / 64
                                             << (cls.both[i] ? " (real+virtual shadow)" : "");
      } else if (cls.expect[i] == Expect::Darker) {
        ++darker;
        // No ambient is blocked in the baseline, so the virtual umbra is the ambient share.
        EXPECT_LT(lin(o[0]), 0.6f * lin(c[0])) << "pixel " << i % 64 << "," << i / 64;
      }
    }
    // The test must test something in every class.
    EXPECT_GT(darker, 10);
    EXPECT_GT(unchanged, 200);
    EXPECT_GT(both, 3);
  }
}

// The lamp's bounce off the objects (shading/environment_occlusion.h lights_bounce): the floor
// within 10 cm of the red boxes gains red light, more than green (box albedo red 0.8, green
// 0.2), and the floor farther than 40 cm from them much less.
TEST_F(BaselineTest, TheLampsBounceOffTheBoxesReddensTheFloorBesideThem) {
  auto with = create_runtime(settings_for(0, true), scene_.cameras(), scene_.scene);
  auto without = create_runtime(settings_for(0, false), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(with.ok()) << with.error().message;
  ASSERT_TRUE(without.ok()) << without.error().message;
  const auto a = run(**with, {scene_.frame(0)}), b = run(**without, {scene_.frame(0)});
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  glm::dvec3 near(0.0), far(0.0);
  int n_near = 0, n_far = 0;
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u) {
      const SurfaceHit hit = scene_.trace(u, v, true);
      if (hit.kind != SurfaceKind::Floor) continue;
      float nearest = 1e9f;
      for (const Box& box : scene_.virtual_boxes)
        nearest = std::min(nearest, glm::length(glm::max(glm::max(box.lo - hit.point, hit.point - box.hi), glm::vec3(0.0f))));
      const size_t o = (size_t(v) * 64 + u) * 4;
      const glm::dvec3 gain(lin(a[0].image.data[o]) - lin(b[0].image.data[o]),
                            lin(a[0].image.data[o + 1]) - lin(b[0].image.data[o + 1]),
                            lin(a[0].image.data[o + 2]) - lin(b[0].image.data[o + 2]));
      if (nearest <= 0.1f) near += gain, ++n_near;
      if (nearest > 0.4f) far += gain, ++n_far;
    }
  ASSERT_GT(n_near, 10);
  ASSERT_GT(n_far, 10);
  near /= double(n_near);
  far /= double(n_far);
  EXPECT_GT(near.x, 0.002) << "red gain beside the boxes";
  EXPECT_GT(near.x, 2.0 * near.y) << "the boxes' colour";
  // Measured: red +0.024 beside them, +0.006 beyond 40 cm (the boxes subtend less there).
  EXPECT_LT(far.x, 0.35 * near.x) << "the bounce falls off with distance from the boxes";
  EXPECT_GE(far.x, -1e-4) << "no light taken";
}

TEST_F(BaselineTest, VirtualPixelsCarryTheObjectsShadingAndTheMask) {
  auto rt = create_runtime(settings_for(0), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  const auto outs = run(**rt, {scene_.frame(0)});
  ASSERT_EQ(outs.size(), 1u);
  const FrameOutput& out = outs[0];
  ASSERT_EQ(out.virtual_mask.width, 64);
  int tested = 0, virtual_pixels = 0;
  for (int v = 1; v < 47; ++v) {
    for (int u = 1; u < 63; ++u) {
      const SurfaceHit h = scene_.trace(u, v, true);
      // Mask agrees with the analytic scene away from outlines.
      bool interior = true;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du)
          interior = interior && (scene_.trace(u + du, v + dv, true).kind == SurfaceKind::Virtual) ==
                                     (h.kind == SurfaceKind::Virtual);
      if (!interior) continue;
      const uint8_t m = out.virtual_mask.at(u, v)[0];
      EXPECT_EQ(m != 0, h.kind == SurfaceKind::Virtual) << u << "," << v;
      if (h.kind != SurfaceKind::Virtual) continue;
      ++virtual_pixels;
      // Top faces (normal up) not shadowed by the other box: Lambert with the base colour
      // (GGX's diffuse share at F0 = 0.04 is within a few percent), plus the ambient.
      if (h.normal.y < 0.5f) continue;
      const glm::vec3 p = h.point + h.normal * 1e-4f;
      if (scene_.blocked_by_virtual(p) || scene_.blocked_by_real(p)) continue;
      const float e = scene_.direct(p, h.normal);
      const uint8_t* o = out.image.at(u, v);
      for (int ch = 0; ch < 3; ++ch) {
        const float base = scene_.virtual_base[ch];
        const float expected = std::min(1.0f, base * scene_.ambient + base / shader::MRGI_PI * e);
        EXPECT_NEAR(lin(o[ch]), expected, 0.08f * expected + 0.004f) << u << "," << v << " ch " << ch;
      }
      ++tested;
    }
  }
  EXPECT_GT(virtual_pixels, 40);
  EXPECT_GT(tested, 10);
}

TEST_F(BaselineTest, AllZeroDepthLeavesRealPixelsUntouched) {
  auto rt = create_runtime(settings_for(1), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  InputFrame f = scene_.frame(0);
  std::fill(f.depth.data.begin(), f.depth.data.end(), uint16_t(0));
  const auto outs = run(**rt, {f});
  ASSERT_EQ(outs.size(), 1u);
  const FrameOutput& out = outs[0];
  int real = 0;
  for (size_t i = 0; i < out.virtual_mask.data.size(); ++i) {
    EXPECT_EQ(out.image.data[i * 4 + 3], 255);
    if (out.virtual_mask.data[i] != 0) continue;  // the virtual boxes are still drawn
    ++real;
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_NEAR(int(out.image.data[i * 4 + ch]), int(f.color.data[i * 3 + ch]), 1) << "pixel " << i;
  }
  EXPECT_GT(real, 1000);
}

TEST_F(BaselineTest, ExtremeInputsGiveFiniteOutput) {
  // Depth at the u16 maximum, single-pixel spikes, saturated and black colour, no pose: nothing
  // may turn into NaN-garbage (an 8-bit NaN shows as 0 or 255 noise; the pattern is checked).
  auto rt = create_runtime(settings_for(0), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  InputFrame f = scene_.frame(0);
  for (size_t i = 0; i < f.depth.data.size(); ++i) {
    if (i % 7 == 0) f.depth.data[i] = 65535;
    if (i % 11 == 0) f.depth.data[i] = 1;
    if (i % 13 == 0) f.color.data[i * 3] = 255;
    if (i % 17 == 0) f.color.data[i * 3 + 1] = 0;
  }
  f.pose.reset();
  const auto outs = run(**rt, {f});
  ASSERT_EQ(outs.size(), 1u);
  ASSERT_FALSE(outs[0].stats.notes.empty());
  EXPECT_NE(outs[0].stats.notes[0].find("pose"), std::string::npos);
  for (size_t i = 0; i < outs[0].virtual_mask.data.size(); ++i) EXPECT_EQ(outs[0].image.data[i * 4 + 3], 255);
}

TEST_F(BaselineTest, MemoryIsAllocatedOnceAndStatsNamePasses) {
  auto rt = create_runtime(settings_for(0), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  const double before = (*rt)->memory_mib();
  EXPECT_GT(before, 16.0);  // at least one 2048^2 depth map
  std::vector<InputFrame> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(scene_.frame(i));
  const auto outs = run(**rt, frames);
  ASSERT_EQ(outs.size(), 6u);
  ASSERT_TRUE((*rt)->set_level(3).ok());
  const auto more = run(**rt, frames);
  ASSERT_EQ(more.size(), 6u);
  EXPECT_EQ((*rt)->memory_mib(), before);
  for (size_t i = 0; i < outs.size(); ++i) EXPECT_EQ(outs[i].stats.frame_index, int64_t(i));
  EXPECT_EQ(more.back().stats.level, 3);
  const FrameStats& st = outs.back().stats;
  for (const char* pass : {"recon_positions", "recon_normals", "virtual_gbuffer", "shadow_primary",
                           "shadow_virtual_casters", "shade_direct", "compose"}) {
    bool found = false;
    for (const PassTiming& p : st.passes) found = found || p.name == pass;
    EXPECT_TRUE(found) << pass;
  }
  EXPECT_GT(st.gpu_total_ms, 0.0);
  EXPECT_FALSE((*rt)->set_level(4).ok());
}

TEST_F(BaselineTest, SkipsAreReportedWithAReason) {
  SceneDesc no_virtual = scene_.scene;
  no_virtual.virtual_objects.clear();
  auto rt = create_runtime(settings_for(2), scene_.cameras(), no_virtual);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  const InputFrame f = scene_.frame(0);
  const auto outs = run(**rt, {f});
  ASSERT_EQ(outs.size(), 1u);
  bool reported = false;
  for (const std::string& s : outs[0].stats.skipped)
    reported = reported || s.find("technique: no virtual object and no virtual lamp") != std::string::npos;
  EXPECT_TRUE(reported);
  // Nothing virtual: the output is the camera frame.
  for (size_t i = 0; i < f.color.data.size() / 3; ++i)
    ASSERT_NEAR(int(outs[0].image.data[i * 4 + 1]), int(f.color.data[i * 3 + 1]), 1) << i;
}

TEST_F(BaselineTest, BadFramesAndSettingsAreRefused) {
  auto unknown = create_runtime([] { auto s = settings_for(0); s.technique = "nope"; return s; }(),
                                scene_.cameras(), scene_.scene);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(unknown.error().message.find("baseline"), std::string::npos);
  auto bad_level = create_runtime(settings_for(9), scene_.cameras(), scene_.scene);
  ASSERT_FALSE(bad_level.ok());
  EXPECT_EQ(bad_level.error().kind, ErrorKind::BadUsage);

  auto rt = create_runtime(settings_for(3), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  InputFrame f = scene_.frame(0);
  f.depth = ImageU16(32, 24);
  auto r = (*rt)->process(f);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::BadInput);
  EXPECT_NE(r.error().message.find("depth intrinsics' size 64x48"), std::string::npos) << r.error().message;
  // The runtime is still usable afterwards.
  const auto outs = run(**rt, {scene_.frame(1)});
  EXPECT_EQ(outs.size(), 1u);
}

TEST(TechniqueRegistry, NamesAndLevels) {
  const auto names = technique_names();
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names[0], "baseline");
  auto levels = technique_levels("baseline");
  ASSERT_TRUE(levels.ok());
  EXPECT_EQ((*levels)[0], "high");
  EXPECT_EQ(levels->back(), "lowest");
  auto none = technique_levels("does-not-exist");
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().kind, ErrorKind::BadUsage);
}

}  // namespace
}  // namespace mrgi::test

namespace mrgi::test {
namespace {

// Under an environment (no lamp), the virtual box shadows the sky for the real
// floor at its foot: the light stage's strongest environment regions are drawn with shadow maps.
// A sky bright above and dark below; floor pixels just outside the box's footprint get darker,
// floor pixels far from every object keep the camera's value.
TEST_F(BaselineTest, AVirtualObjectUnderASkyCastsAContactShadow) {
  scene_.scene.lights.clear();
  ImageRGB8 sky(32, 16);
  for (int v = 0; v < 16; ++v)
    for (int u = 0; u < 32; ++u)
      for (int c = 0; c < 3; ++c) sky.at(u, v)[c] = uint8_t(v < 8 ? 200 : 20);  // the upper half bright
  ASSERT_TRUE(write_png(scene_.scene.environment.image, sky).ok());
  auto rt = create_runtime(settings_for(0), scene_.cameras(), scene_.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  const InputFrame input = scene_.frame(0);
  const auto outs = run(**rt, {input});
  ASSERT_EQ(outs.size(), 1u);
  const FrameOutput& out = outs[0];
  bool noted = false;
  for (const std::string& n : out.stats.notes) noted = noted || n.find("light: environment image") == 0;
  EXPECT_TRUE(noted);
  const Box& box = scene_.virtual_boxes[0];  // on the floor
  double near_ratio = 0.0, far_ratio = 0.0;
  int near = 0, far = 0;
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      const SurfaceHit h = scene_.trace(u, v, true);
      if (h.kind != SurfaceKind::Floor) continue;
      const float dx = std::max({box.lo.x - h.point.x, h.point.x - box.hi.x, 0.0f});
      const float dz = std::max({box.lo.z - h.point.z, h.point.z - box.hi.z, 0.0f});
      const float gap = std::sqrt(dx * dx + dz * dz);
      const uint8_t* o = out.image.at(u, v);
      const uint8_t* c = input.color.at(u, v);
      const double ratio = (double(o[0]) + 1.0) / (double(c[0]) + 1.0);
      if (gap > 0.03f && gap < 0.12f) {
        near_ratio += ratio;
        ++near;
      } else if (std::abs(h.point.x) > 0.7f && h.point.z < -0.2f) {  // away from both boxes
        far_ratio += ratio;
        ++far;
      }
    }
  }
  ASSERT_GT(near, 5);
  ASSERT_GT(far, 5);
  near_ratio /= near;
  far_ratio /= far;
  // Measured 0.91: four of the sixteen median-cut regions are shadowed, and the
  // sky's share they carry is half the light; without the shadowed regions it is 1.
  EXPECT_LT(near_ratio, 0.95) << "no contact shadow at the box's foot";
  EXPECT_NEAR(far_ratio, 1.0, 0.03) << "open floor changed";
}

// The environment occlusion's near field (shading/environment_occlusion.h): what a virtual
// object hides from a floor point is the sky only where nothing real lies beyond it. A black
// virtual box (it shows nothing in place of what it hides) stands beside a tall real block under
// a bright uniform sky: floor points beside its -x face look through it at the block (near
// field: they lose the block's radiance), floor points beside its +z face look through it
// mostly at the open sky and lose the sky's. Without the rule both sides darken alike (the box,
// the sky and the distances are symmetric: 0.36 and 0.36 measured with the rule switched off);
// and a brighter block takes more from the points that see it through the box.
struct NearFieldDarkening {
  double toward_block = 0.0, toward_sky = 0.0;
};
NearFieldDarkening near_field_darkening(float block_albedo, int level_index) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str(), glm::vec3(0.0f), glm::vec3(0.0f));
  scene.scene.lights.clear();
  scene.lamp.intensity = 0.0f;
  scene.box_albedo = block_albedo;
  scene.real_box = {{0.25f, 0.0f, -1.0f}, {0.6f, 0.8f, -0.2f}};  // beyond the box's +x face (0.05 m gap)
  scene.scene.virtual_objects.resize(1);                        // the box on the floor only
  scene.virtual_boxes.resize(1);
  const uint8_t level = 188;
  ImageRGB8 sky(16, 8, level);
  EXPECT_TRUE(write_png(scene.scene.environment.image, sky).ok());
  scene.ambient = shader::srgb_decode1(float(level) / 255.0f);
  const Box& box = scene.virtual_boxes[0];  // x, z in [-0.2, 0.2] x [-0.8, -0.4]
  const auto outs = run_synthetic_frames(scene, settings_for(level_index), 1);
  NearFieldDarkening d;
  if (outs.size() != 1u) {
    ADD_FAILURE() << "no frame";
    return d;
  }
  const InputFrame input = scene.frame(0);
  int n_block = 0, n_sky = 0;
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u) {
      const SurfaceHit h = scene.trace(u, v, true);
      if (h.kind != SurfaceKind::Floor) continue;
      const float gx = box.lo.x - h.point.x;  // beside the -x face: looks along +x at the block
      const float gz = h.point.z - box.hi.z;  // beside the +z face: looks along -z at the sky
      const double darkening = 1.0 - (lin(outs[0].image.at(u, v)[1]) + 1e-3) / (lin(input.color.at(u, v)[1]) + 1e-3);
      if (gx > 0.04f && gx < 0.16f && h.point.z > -0.68f && h.point.z < -0.52f) {
        d.toward_block += darkening;
        ++n_block;
      } else if (gz > 0.04f && gz < 0.16f && std::abs(h.point.x) < 0.08f) {
        d.toward_sky += darkening;
        ++n_sky;
      }
    }
  EXPECT_GT(n_block, 3);
  EXPECT_GT(n_sky, 3);
  d.toward_block /= std::max(n_block, 1);
  d.toward_sky /= std::max(n_sky, 1);
  return d;
}

TEST(BaselineNearField, AnObjectHidesTheRealSurfaceBeyondItNotTheSky) {
  // Measured: a block of albedo 0.02 at level 0 0.145 against 0.285, level 1 0.117 against 0.265.
  for (int level_index : {0, 1}) {
    const NearFieldDarkening dark = near_field_darkening(0.02f, level_index);
    EXPECT_GT(dark.toward_sky, 0.03) << "level " << level_index << ": no occlusion of the sky beside the box";
    EXPECT_LT(dark.toward_block, 0.7 * dark.toward_sky)
        << "level " << level_index << ": the block beyond the box was hidden as if it were the sky";
  }
  // What is hidden is the block's radiance as the camera sees it: a brighter block, more
  // (measured at level 1: 0.117 with albedo 0.02, 0.175 with 0.3).
  const NearFieldDarkening dark = near_field_darkening(0.02f, 1), bright = near_field_darkening(0.3f, 1);
  EXPECT_GT(bright.toward_block, dark.toward_block + 0.03)
      << "the block's radiance is not what the box hides from the points that see it through the box";
}

}  // namespace
}  // namespace mrgi::test
