// Virtual objects that move (Runtime::set_object_placement, scene.json motion): for every
// technique at its cheapest level, the object is drawn where it is this frame (the virtual mask
// against the analytic scene traced with the box at its new place), nothing is allocated (the
// start-up memory is unchanged), bad placements are refused, and keyframed motion places it at
// each frame's timestamp.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace {
using namespace mrgi;
using mrgi::test::SyntheticScene;

using mrgi::test::cheapest_runtime;
using mrgi::test::mask_iou;
using mrgi::test::run_frames;

SyntheticScene moved(SyntheticScene s, const glm::vec3& by) {
  s.scene.virtual_objects[0].placement.position += by;
  s.virtual_boxes[0].lo += by;
  s.virtual_boxes[0].hi += by;
  return s;
}

TEST(DynamicScene, AMovedObjectIsDrawnWhereItIsWithoutAllocating) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  ASSERT_GE(scene.scene.virtual_objects.size(), 1u);  // object 0 moves, the others stay
  const glm::vec3 step(0.25f, 0.0f, 0.1f);
  const SyntheticScene after = moved(scene, step);
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    auto rt = cheapest_runtime(technique, scene);
    ASSERT_TRUE(rt);
    Runtime& r = *rt;
    EXPECT_EQ(r.object_count(), scene.scene.virtual_objects.size());
    const double memory = r.memory_mib();
    const std::vector<FrameOutput> outs = run_frames(r, scene, 6, [&](int k) {
      if (k != 3) return;
      Placement p = scene.scene.virtual_objects[0].placement;
      p.position += step;
      EXPECT_TRUE(r.set_object_placement(0, p).ok());
    });
    ASSERT_EQ(outs.size(), 6u);
    for (const FrameOutput& out : outs) {
      const bool later = out.stats.frame_index >= 3;
      const double iou_here = mask_iou(out, later ? after : scene), iou_other = mask_iou(out, later ? scene : after);
      EXPECT_GT(iou_here, 0.8) << "frame " << out.stats.frame_index;
      EXPECT_LT(iou_other, iou_here - 0.15) << "frame " << out.stats.frame_index;
    }
    EXPECT_EQ(r.memory_mib(), memory) << "moving an object allocated";
    // Refused: an index out of range, a non-positive scale, a NaN.
    Placement bad = scene.scene.virtual_objects[0].placement;
    EXPECT_EQ(r.set_object_placement(r.object_count(), bad).error().kind, ErrorKind::BadUsage);
    bad.scale = glm::vec3(0.0f);
    EXPECT_EQ(r.set_object_placement(0, bad).error().kind, ErrorKind::BadUsage);
    bad = scene.scene.virtual_objects[0].placement;
    bad.position.x = std::nanf("");
    EXPECT_EQ(r.set_object_placement(0, bad).error().kind, ErrorKind::BadUsage);
  }
}

SyntheticScene without_object0(SyntheticScene s) {
  s.virtual_boxes.erase(s.virtual_boxes.begin());
  return s;
}

// Removing and adding objects (Runtime::set_object_visible): a removed object is not drawn; with
// every object removed the frame is the camera's; shown again, it is back where it was.
TEST(DynamicScene, RemovedObjectsAreNotDrawnAndComeBack) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  ASSERT_GE(scene.scene.virtual_objects.size(), 2u);
  const SyntheticScene one_less = without_object0(scene);
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    auto rt = cheapest_runtime(technique, scene);
    ASSERT_TRUE(rt);
    Runtime& r = *rt;
    const double memory = r.memory_mib();
    const std::vector<FrameOutput> outs = run_frames(r, scene, 8, [&](int k) {
      if (k == 2) {
        EXPECT_TRUE(r.set_object_visible(0, false).ok());
      }
      for (size_t i = 1; k == 4 && i < r.object_count(); ++i) {
        EXPECT_TRUE(r.set_object_visible(i, false).ok());
      }
      for (size_t i = 0; k == 6 && i < r.object_count(); ++i) {
        EXPECT_TRUE(r.set_object_visible(i, true).ok());
      }
    });
    ASSERT_EQ(outs.size(), 8u);
    for (const FrameOutput& out : outs) {
      const int64_t k = out.stats.frame_index;
      if (k < 2 || k >= 6) {
        EXPECT_GT(mask_iou(out, scene), 0.8) << "frame " << k;
      } else if (k < 4) {
        EXPECT_GT(mask_iou(out, one_less), 0.8) << "frame " << k;
        EXPECT_LT(mask_iou(out, scene), mask_iou(out, one_less)) << "frame " << k;
      } else {
        int masked = 0;
        for (uint8_t m : out.virtual_mask.data) masked += m != 0;
        EXPECT_EQ(masked, 0) << "frame " << k << ": nothing is shown";
      }
    }
    EXPECT_EQ(r.memory_mib(), memory);
    EXPECT_EQ(r.set_object_visible(r.object_count(), true).error().kind, ErrorKind::BadUsage);
  }
}

// scene.json's keyframed motion: the box at its first key for the frames before the second key's
// time, then at the last (held past the last key), with the frames' timestamps (30 fps).
TEST(DynamicScene, KeyframedMotionPlacesTheObjectAtEachFramesTime) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  const glm::vec3 step(-0.2f, 0.0f, 0.15f);
  const SyntheticScene after = moved(scene, step);
  PoseKey a{0.0, scene.scene.virtual_objects[0].placement};
  PoseKey b{3.0 / 30.0, after.scene.virtual_objects[0].placement};
  // Keys that hold the start until frame 2 and reach the end at frame 3.
  PoseKey hold{2.0 / 30.0, a.placement};
  scene.scene.virtual_objects[0].motion = {a, hold, b};
  RuntimeSettings settings;
  settings.level = int(technique_levels(settings.technique)->size()) - 1;
  const std::vector<FrameOutput> outs = mrgi::test::run_synthetic_frames(scene, settings, 6);
  ASSERT_EQ(outs.size(), 6u);
  for (const FrameOutput& out : outs) {
    const int64_t k = out.stats.frame_index;
    if (k <= 2) {
      EXPECT_GT(mask_iou(out, scene), 0.8) << "frame " << k;
      EXPECT_LT(mask_iou(out, after), mask_iou(out, scene) - 0.15) << "frame " << k;
    } else {
      EXPECT_GT(mask_iou(out, after), 0.8) << "frame " << k;
      EXPECT_LT(mask_iou(out, scene), mask_iou(out, after) - 0.15) << "frame " << k;
    }
  }
  // Halfway between two keys: position and scale linear, rotation by slerp.
  const Placement mid = placement_at({a, b}, 1.5 / 30.0);
  const glm::vec3 want = 0.5f * (a.placement.position + b.placement.position);
  EXPECT_NEAR(mid.position.x, want.x, 1e-5f);
  EXPECT_NEAR(mid.position.z, want.z, 1e-5f);
  EXPECT_EQ(placement_at({a, b}, -1.0).position, a.placement.position);
  EXPECT_EQ(placement_at({a, b}, 10.0).position, b.placement.position);
}

}  // namespace

namespace {
// Mean luminance (8-bit sRGB, Rec. 709 weights) of an output's virtual pixels.
double virtual_luma(const mrgi::FrameOutput& out) {
  double sum = 0.0;
  int n = 0;
  for (int v = 0; v < out.image.height; ++v)
    for (int u = 0; u < out.image.width; ++u)
      if (out.virtual_mask.at(u, v)[0] != 0) {
        const uint8_t* p = out.image.at(u, v);
        sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        ++n;
      }
  return n > 0 ? sum / n : 0.0;
}
}  // namespace

// Lamps change at run time (Runtime::set_lamp): dimmed to 0 the virtual objects lose its light
// (the ambient remains), back on they have it again; a lamp whose kind would change, or that
// scene.json would refuse, is refused naming the field; nothing is allocated.
TEST(DynamicScene, ALampTurnedOffAndOnLightsTheObjectsAccordingly) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  ASSERT_EQ(scene.scene.lights.size(), 1u);
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    auto rt = cheapest_runtime(technique, scene);
    ASSERT_TRUE(rt);
    Runtime& r = *rt;
    ASSERT_EQ(r.lamp_count(), 1u);
    const double memory = r.memory_mib();
    const std::vector<FrameOutput> outs = run_frames(r, scene, 9, [&](int k) {
      LightDesc lamp = scene.scene.lights[0];
      if (k >= 3 && k < 6) lamp.intensity = 0.0f;
      EXPECT_TRUE(r.set_lamp(0, lamp).ok());
    });
    ASSERT_EQ(outs.size(), 9u);
    double on = 0.0, off = 0.0, again = 0.0;
    for (const FrameOutput& out : outs) {
      const int64_t k = out.stats.frame_index;
      (k < 3 ? on : k < 6 ? off : again) += virtual_luma(out) / 3.0;
    }
    if (technique == "ssrt") {
      // ssrt lights with its own estimate from the frames (its paper has no lamps): the
      // declared lamp changes nothing there, and the call is still accepted.
      EXPECT_NEAR(off, on, 1e-9);
    } else {
      EXPECT_LT(off, 0.8 * on) << "on " << on << ", off " << off;
      EXPECT_NEAR(again, on, 0.05 * on);
    }
    EXPECT_EQ(r.memory_mib(), memory);
    LightDesc bad = scene.scene.lights[0];
    bad.intensity = -1.0f;
    EXPECT_EQ(r.set_lamp(0, bad).error().kind, ErrorKind::BadUsage);
    bad = scene.scene.lights[0];
    bad.type = LightType::Directional;
    auto refused = r.set_lamp(0, bad);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("type"), std::string::npos) << refused.error().message;
    EXPECT_EQ(r.set_lamp(1, scene.scene.lights[0]).error().kind, ErrorKind::BadUsage);
  }
}

namespace {
// scene.json's lamp motion gives the frames an app gets by setting the lamp where the motion has
// it every frame (Runtime::set_lamp with lamp_at): the same pixels, for every technique; and it
// changes them (the lamp swings away and dims).
TEST(DynamicScene, KeyframedLampMotionIsTheLampAtEachFramesTime) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  SceneDesc moving = scene.scene;
  LightDesc& lamp = moving.lights[0];
  const double t1 = scene.frame(5).timestamp;
  lamp.motion = {{scene.frame(0).timestamp, lamp.position, lamp.direction, lamp.intensity},
                 {t1, lamp.position + glm::vec3(0.6f, 0.0f, 0.2f), lamp.direction, 0.3f * lamp.intensity}};
  for (const std::string& technique : technique_names()) {
    if (technique == "ssrt") continue;  // lit by its own estimate: declared lamps light nothing there
    SCOPED_TRACE(technique);
    RuntimeSettings settings;
    settings.technique = technique;
    settings.level = int(technique_levels(technique)->size()) - 1;
    auto by_motion = create_runtime(settings, scene.cameras(), moving);
    ASSERT_TRUE(by_motion.ok()) << by_motion.error().message;
    const std::vector<FrameOutput> a = run_frames(**by_motion, scene, 6, [](int) {});
    auto by_hand = create_runtime(settings, scene.cameras(), scene.scene);
    ASSERT_TRUE(by_hand.ok());
    Runtime& r = **by_hand;
    const std::vector<FrameOutput> b = run_frames(r, scene, 6, [&](int k) {
      EXPECT_TRUE(r.set_lamp(0, lamp_at(moving.lights[0], scene.frame(k).timestamp)).ok());
    });
    ASSERT_EQ(a.size(), 6u);
    ASSERT_EQ(b.size(), 6u);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].image.data, b[i].image.data) << "frame " << i;
    EXPECT_NE(a.front().image.data, a.back().image.data) << "the lamp's motion changed nothing";
  }
}
}  // namespace
