// --technique auto (mrgi/runtime.h choose_technique): techniques a scene cannot use are left
// out (no lamp: dlpv and dir; a glossy virtual material: ssrt), the most accurate level that fits
// the budget decides, and a runtime made with "auto" runs the chosen technique and says why on
// its first frame.
#include <gtest/gtest.h>

#include <filesystem>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace {
using namespace mrgi;
using mrgi::test::SyntheticScene;

const std::vector<TechniqueFigure> kTable = {
    {"baseline", 0, 100.0, 0.30}, {"baseline", 3, 20.0, 0.40}, {"ssrt", 2, 25.0, 0.35},
    {"dlpv", 3, 26.0, 0.33},      {"dir", 3, 27.0, 0.20},      {"dir", 0, 500.0, 0.10},
};

TEST(TechniqueChoice, LeavesOutWhatTheSceneCannotUseAndTakesTheMostAccurateFit) {
  mrgi::testing::TempDir dir;
  std::filesystem::create_directories(dir.str() + "/d");
  std::filesystem::create_directories(dir.str() + "/g");
  const SyntheticScene diffuse = SyntheticScene::create(dir.str() + "/d");
  // With the lamp: dir's level 3 fits 28.3 ms (33.3 less 15 %) with the lowest RDE.
  auto c = choose_technique(diffuse.scene, 33.3, kTable);
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->technique, "dir") << c->reason;
  // A budget nothing fits: the fastest level's technique.
  c = choose_technique(diffuse.scene, 10.0, kTable);
  EXPECT_EQ(c->technique, "baseline") << c->reason;
  EXPECT_NE(c->reason.find("no level fits"), std::string::npos) << c->reason;
  // No lamp: the RSM-based techniques are out, ssrt's 0.35 beats baseline's 0.40.
  SceneDesc no_lamp = diffuse.scene;
  no_lamp.lights.clear();
  c = choose_technique(no_lamp, 33.3, kTable);
  EXPECT_EQ(c->technique, "ssrt") << c->reason;
  EXPECT_NE(c->reason.find("dir left out: no lamp"), std::string::npos) << c->reason;
  // A glossy object and no lamp: ssrt is out too.
  const SyntheticScene glossy = SyntheticScene::create(dir.str() + "/g", glm::vec3(0.0f), glm::vec3(0.8f), 1.0f, 0.2f);
  SceneDesc glossy_no_lamp = glossy.scene;
  glossy_no_lamp.lights.clear();
  c = choose_technique(glossy_no_lamp, 33.3, kTable);
  EXPECT_EQ(c->technique, "baseline") << c->reason;
  EXPECT_NE(c->reason.find("ssrt left out: a glossy virtual material"), std::string::npos) << c->reason;
  // No glossy material in scene.json, but room for glossy objects added at run time: ssrt is out.
  c = choose_technique(no_lamp, 33.3, kTable, SchedulerSettings{}.headroom, true);
  EXPECT_EQ(c->technique, "baseline") << c->reason;
  EXPECT_NE(c->reason.find("ssrt left out: room for glossy objects added at run time"), std::string::npos) << c->reason;
  // A glTF that cannot be read is refused by name.
  SceneDesc broken = diffuse.scene;
  broken.virtual_objects[0].gltf = dir.str() + "/missing.glb";
  auto bad = choose_technique(broken, 33.3, kTable);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("missing.glb"), std::string::npos) << bad.error().message;
}

TEST(TechniqueChoice, AutoRuntimeRunsTheChosenTechniqueAndSaysWhy) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  RuntimeSettings s;
  s.technique = "auto";
  s.technique_table = kTable;
  s.device.validate = true;
  auto rt = create_runtime(s, scene.cameras(), scene.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  EXPECT_EQ((*rt)->technique(), "dir");
  auto outs = (*rt)->process(scene.frame(0));
  ASSERT_TRUE(outs.ok());
  auto rest = (*rt)->flush();
  ASSERT_TRUE(rest.ok());
  ASSERT_EQ(rest->size() + outs->size(), 1u);
  const FrameOutput& out = outs->empty() ? rest->front() : outs->front();
  bool said = false;
  for (const std::string& n : out.stats.notes) said = said || n.find("technique: auto: dir chosen") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_TRUE(out.stats.scheduled);
  // A table row that is not a measurement is refused with its field.
  s.technique_table = {{"dir", 3, -1.0, 0.2}};
  auto bad = create_runtime(s, scene.cameras(), scene.scene);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("technique_table"), std::string::npos) << bad.error().message;
}

}  // namespace
