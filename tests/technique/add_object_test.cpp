// Objects an app adds and removes while the runtime runs (Runtime::add_object, remove_object),
// within the room stated at creation (RuntimeSettings::objects), for every technique at its
// cheapest level:
//   - an object added before the first frame gives the frames of the same object declared in
//     scene.json, value for value (its meshes, levels of detail, material, texture layer, the
//     ISMs' triangle list and the voxelisation are the declared one's);
//   - added after some frames it is drawn where it is placed from the next frame, and removed,
//     it is gone from the next frame; nothing is allocated on the way;
//   - a full room (slots, triangles, textures), a material the runtime was not prepared for,
//     a mirror and an unreadable file are refused by name, and the frames after a refusal are
//     those of a runtime that never saw the call.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/temp_dir.h"
#include "mrgi/image.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace {
using namespace mrgi;
using mrgi::test::SyntheticScene;

using mrgi::test::mask_iou;
using mrgi::test::run_frames;

// Room for one cube (24 vertices, 12 triangles, one primitive) and `textures` texture layers.
ObjectCapacity room_for_one(int textures = 0) {
  ObjectCapacity room;
  room.objects = 1;
  room.meshes = 1;
  room.triangles = 12;
  room.vertices = 24;
  room.textures = textures;
  room.texture_side = 8;
  return room;
}

// The cheapest level of `technique` with `room` for added objects, validation on (a message
// fails the frame).
std::unique_ptr<Runtime> room_runtime(const std::string& technique, const SyntheticScene& scene,
                                          const ObjectCapacity& room = {}) {
  RuntimeSettings settings;
  settings.objects = room;
  settings.device.validate = true;
  return mrgi::test::cheapest_runtime(technique, scene, settings);
}

// The scene as scene.json would have it without its last object (the one the app adds).
SyntheticScene without_last(SyntheticScene s) {
  s.scene.virtual_objects.pop_back();
  s.virtual_boxes.pop_back();
  return s;
}

// Every value of the composite and the mask equal (reported as how many differ and by how much).
void expect_same_frames(const std::vector<FrameOutput>& a, const std::vector<FrameOutput>& b) {
  ASSERT_EQ(a.size(), b.size());
  auto differ = [](const std::vector<uint8_t>& x, const std::vector<uint8_t>& y, int& largest) {
    size_t n = 0;
    largest = 0;
    for (size_t i = 0; i < x.size() && i < y.size(); ++i)
      if (x[i] != y[i]) {
        ++n;
        largest = std::max(largest, std::abs(int(x[i]) - int(y[i])));
      }
    return n + (x.size() > y.size() ? x.size() - y.size() : y.size() - x.size());
  };
  for (size_t k = 0; k < a.size(); ++k) {
    int largest = 0;
    EXPECT_EQ(differ(a[k].image.data, b[k].image.data, largest), 0u) << "frame " << k << ": largest difference " << largest;
    EXPECT_EQ(differ(a[k].virtual_mask.data, b[k].virtual_mask.data, largest), 0u) << "frame " << k << " mask";
  }
}

TEST(AddObject, AnObjectAddedBeforeTheFirstFrameGivesTheDeclaredObjectsFrames) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  ASSERT_EQ(scene.scene.virtual_objects.size(), 2u);
  const SyntheticScene first = without_last(scene);
  const VirtualObjectDesc& added = scene.scene.virtual_objects.back();
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    auto declared = room_runtime(technique, scene);
    auto app = room_runtime(technique, first, room_for_one());
    ASSERT_TRUE(declared && app);
    EXPECT_EQ(app->object_count(), 2u);
    EXPECT_FALSE(app->has_object(1));
    auto slot = app->add_object(added.gltf, added.placement);
    ASSERT_TRUE(slot.ok()) << slot.error().message;
    EXPECT_EQ(*slot, 1u);
    EXPECT_TRUE(app->has_object(1));
    expect_same_frames(run_frames(*declared, scene, 4), run_frames(*app, first, 4));
  }
}

// A textured object: its texture goes into a free layer of the array at add_object.
TEST(AddObject, ATexturedObjectAddedGivesTheDeclaredObjectsFrames) {
  mrgi::testing::TempDir dir;
  SyntheticScene scene = SyntheticScene::create(dir.str());
  // The cube with a base-colour texture (no texture coordinates: every point reads texel 0, 0).
  nlohmann::json j;
  std::ifstream(dir.str() + "/cube.gltf") >> j;
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  j["images"] = {{{"uri", "blue.png"}}};
  j["textures"] = {{{"source", 0}}};
  std::ofstream(dir.str() + "/textured.gltf") << j.dump(2);
  ImageRGBA8 blue(8, 8);
  for (size_t i = 0; i < blue.pixel_count(); ++i) {
    blue.data[i * 4 + 0] = 40;
    blue.data[i * 4 + 1] = 90;
    blue.data[i * 4 + 2] = 230;
    blue.data[i * 4 + 3] = 255;
  }
  ASSERT_TRUE(write_png(dir.str() + "/blue.png", blue).ok());
  scene.scene.virtual_objects.back().gltf = dir.str() + "/textured.gltf";
  const SyntheticScene first = without_last(scene);
  const VirtualObjectDesc& added = scene.scene.virtual_objects.back();
  auto declared = room_runtime("baseline", scene);
  auto app = room_runtime("baseline", first, room_for_one(1));
  ASSERT_TRUE(declared && app);
  ASSERT_TRUE(app->add_object(added.gltf, added.placement).ok());
  const std::vector<FrameOutput> a = run_frames(*declared, scene, 2);
  const std::vector<FrameOutput> b = run_frames(*app, first, 2);
  expect_same_frames(a, b);
  // Without room for a texture the same object is refused, naming the room's field.
  auto no_room = room_runtime("baseline", first, room_for_one(0));
  ASSERT_TRUE(no_room);
  auto refused = no_room->add_object(added.gltf, added.placement);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(refused.error().message.find("objects.textures"), std::string::npos) << refused.error().message;
}

// Added at frame 3 and removed at frame 6: drawn where it is placed in between, gone before and
// after, with every technique and without allocating.
TEST(AddObject, AddedAndRemovedObjectsAreDrawnOnlyWhileTheyArePresent) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  const SyntheticScene first = without_last(scene);
  const VirtualObjectDesc& added = scene.scene.virtual_objects.back();
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    auto rt = room_runtime(technique, first, room_for_one());
    ASSERT_TRUE(rt);
    Runtime& r = *rt;
    const double memory = r.memory_mib();
    const std::vector<FrameOutput> outs = run_frames(r, first, 9, [&](int k) {
      if (k == 3) {
        auto slot = r.add_object(added.gltf, added.placement);
        EXPECT_TRUE(slot.ok()) << slot.error().message;
      }
      if (k == 6) {
        EXPECT_TRUE(r.remove_object(1).ok());
      }
    });
    ASSERT_EQ(outs.size(), 9u);
    for (const FrameOutput& out : outs) {
      const int64_t k = out.stats.frame_index;
      const bool present = k >= 3 && k < 6;
      const SyntheticScene& now = present ? scene : first;
      const SyntheticScene& other = present ? first : scene;
      EXPECT_GT(mask_iou(out, now), 0.8) << "frame " << k;
      EXPECT_LT(mask_iou(out, other), mask_iou(out, now)) << "frame " << k;
      for (uint8_t v : out.image.data) ASSERT_LE(v, 255);
    }
    EXPECT_EQ(r.memory_mib(), memory);
    EXPECT_FALSE(r.has_object(1));
    EXPECT_EQ(r.remove_object(1).error().kind, ErrorKind::BadUsage);  // already empty
    EXPECT_EQ(r.set_object_visible(1, true).error().kind, ErrorKind::BadUsage);
    EXPECT_EQ(r.set_object_placement(1, added.placement).error().kind, ErrorKind::BadUsage);
  }
}

// Refusals name what is full or not prepared for, and change nothing: the frames after them are
// those of a runtime that never saw them.
TEST(AddObject, AFullRoomAndUnpreparedMaterialsAreRefusedCleanly) {
  mrgi::testing::TempDir dir, glossy_dir, mirror_dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  const SyntheticScene first = without_last(scene);
  const VirtualObjectDesc& added = scene.scene.virtual_objects.back();
  const SyntheticScene glossy =
      SyntheticScene::create(glossy_dir.str(), glm::vec3(0.0f), glm::vec3(0.8f, 0.2f, 0.2f), 0.0f, 0.3f);
  const SyntheticScene mirror =
      SyntheticScene::create(mirror_dir.str(), glm::vec3(0.0f), glm::vec3(0.9f), 1.0f, 0.02f);
  auto refused = [](const Expected<size_t>& r, ErrorKind kind, const std::string& names) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, kind);
    EXPECT_NE(r.error().message.find(names), std::string::npos) << r.error().message;
  };
  ObjectCapacity few = room_for_one();
  few.triangles = 11;
  auto small = room_runtime("baseline", first, few);
  ASSERT_TRUE(small);
  refused(small->add_object(added.gltf, added.placement), ErrorKind::BadUsage, "objects.triangles");

  auto rt = room_runtime("baseline", first, room_for_one());
  auto untouched = room_runtime("baseline", first, room_for_one());
  ASSERT_TRUE(rt && untouched);
  refused(rt->add_object(glossy.scene.virtual_objects[0].gltf, added.placement), ErrorKind::BadUsage, "objects.glossy");
  refused(rt->add_object(mirror.scene.virtual_objects[0].gltf, added.placement), ErrorKind::BadUsage, "mirror or glass");
  refused(rt->add_object(dir.str() + "/missing.gltf", added.placement), ErrorKind::NotFound, "missing.gltf");
  Placement bad = added.placement;
  bad.scale.x = 0.0f;
  refused(rt->add_object(added.gltf, bad), ErrorKind::BadUsage, "scale");
  ASSERT_TRUE(rt->add_object(added.gltf, added.placement).ok());
  refused(rt->add_object(added.gltf, added.placement), ErrorKind::BadUsage, "slot");
  ASSERT_TRUE(untouched->add_object(added.gltf, added.placement).ok());
  expect_same_frames(run_frames(*rt, first, 3), run_frames(*untouched, first, 3));

  // A room that was prepared for glossy objects takes one.
  ObjectCapacity prepared = room_for_one();
  prepared.glossy = true;
  auto ready = room_runtime("baseline", first, prepared);
  ASSERT_TRUE(ready);
  EXPECT_TRUE(ready->add_object(glossy.scene.virtual_objects[0].gltf, added.placement).ok());
  // Room settings out of range are refused at creation, naming the field.
  RuntimeSettings settings;
  settings.objects.objects = -1;
  auto bad_room = create_runtime(settings, first.cameras(), first.scene);
  ASSERT_FALSE(bad_room.ok());
  EXPECT_NE(bad_room.error().message.find("objects.objects"), std::string::npos) << bad_room.error().message;
}

}  // namespace
