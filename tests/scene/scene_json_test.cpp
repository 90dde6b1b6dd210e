#include <gtest/gtest.h>

#include <cctype>
#include <ostream>

#include <filesystem>

#include "capture/temp_dir.h"
#include "mrgi/scene.h"

namespace mrgi {
namespace {

using testing::TempDir;
using testing::write_text;

// A folder with a scene.json and the (dummy, never parsed here) files it names.
struct SceneFixture {
  TempDir dir;
  SceneFixture() {
    write_text(dir.file("models/box.glb"), "glb");
    write_text(dir.file("env/sky.exr"), "exr");
  }
  std::string write(const std::string& json) {
    write_text(dir.file("scene.json"), json);
    return dir.file("scene.json");
  }
};

const char* kFullScene = R"({
  "version": 1,
  "virtual_objects": [
    {"gltf": "models/box.glb", "position": [0.5, 0, -1], "rotation": [0, 0.7071068, 0, 0.7071068], "scale": 0.25}
  ],
  "lights": [
    {"type": "point", "real": true, "position": [0, 2, 0], "color": [1, 0.9, 0.8], "intensity": 5},
    {"type": "spot", "real": false, "position": [1, 2, 0], "direction": [0, -2, 0],
     "intensity": 3, "inner_angle_deg": 20, "outer_angle_deg": 35},
    {"type": "directional", "real": true, "direction": [0.3, -1, 0.2], "intensity": 2}
  ],
  "environment": {"real": true, "image": "env/sky.exr", "intensity": 0.5, "rotation": [0, 0, 0, 1]},
  "real_geometry": [
    {"gltf": "models/box.glb", "scale": [2, 1, 3],
     "material": {"base_color": [0.5, 0.4, 0.3], "roughness": 0.7, "metallic": 0}}
  ],
  "real_materials": [
    {"min": [-0.7, 0.7, -0.1], "max": [0.7, 0.76, 0.7], "roughness": 0.2, "metallic": 0.1}
  ]
})";

TEST(SceneJson, ParsesEveryKey) {
  SceneFixture f;
  auto scene = load_scene_json(f.write(kFullScene));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_EQ(scene->virtual_objects.size(), 1u);
  const auto& vo = scene->virtual_objects[0];
  EXPECT_EQ(std::filesystem::path(vo.gltf), std::filesystem::path(f.dir.file("models/box.glb")));
  EXPECT_FLOAT_EQ(vo.placement.position.x, 0.5f);
  EXPECT_FLOAT_EQ(vo.placement.rotation.w, 0.7071068f);  // JSON x y z w -> glm w x y z
  EXPECT_FLOAT_EQ(vo.placement.rotation.y, 0.7071068f);
  EXPECT_EQ(vo.placement.scale, glm::vec3(0.25f));
  ASSERT_EQ(scene->lights.size(), 3u);
  EXPECT_EQ(scene->lights[0].type, LightType::Point);
  EXPECT_FLOAT_EQ(scene->lights[0].color.z, 0.8f);
  EXPECT_EQ(scene->lights[1].type, LightType::Spot);
  EXPECT_FALSE(scene->lights[1].real);
  EXPECT_EQ(scene->lights[1].direction, glm::vec3(0, -1, 0));  // normalised on load
  EXPECT_FLOAT_EQ(scene->lights[1].outer_angle_deg, 35.0f);
  EXPECT_EQ(scene->lights[2].type, LightType::Directional);
  EXPECT_NEAR(glm::length(scene->lights[2].direction), 1.0f, 1e-6f);
  EXPECT_TRUE(scene->environment.present);
  EXPECT_FALSE(scene->environment.from_env_camera);
  EXPECT_FLOAT_EQ(scene->environment.intensity, 0.5f);
  ASSERT_EQ(scene->real_geometry.size(), 1u);
  EXPECT_TRUE(scene->real_geometry[0].has_material_hint);
  EXPECT_EQ(scene->real_geometry[0].placement.scale, glm::vec3(2, 1, 3));
  EXPECT_FLOAT_EQ(scene->real_geometry[0].material.roughness, 0.7f);
  ASSERT_EQ(scene->real_materials.size(), 1u);
  EXPECT_EQ(scene->real_materials[0].min, glm::vec3(-0.7f, 0.7f, -0.1f));
  EXPECT_FLOAT_EQ(scene->real_materials[0].roughness, 0.2f);
  EXPECT_FLOAT_EQ(scene->real_materials[0].metallic, 0.1f);
}

TEST(SceneJson, WriteThenReadRoundTrips) {
  SceneFixture f;
  auto scene = load_scene_json(f.write(kFullScene));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  // Written into a sub-folder: paths must be re-expressed relative to the new file.
  std::filesystem::create_directories(f.dir.file("out"));
  ASSERT_TRUE(write_scene_json(f.dir.file("out/scene.json"), *scene).ok());
  auto back = load_scene_json(f.dir.file("out/scene.json"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->virtual_objects[0].gltf, scene->virtual_objects[0].gltf);
  EXPECT_EQ(back->virtual_objects[0].placement.rotation, scene->virtual_objects[0].placement.rotation);
  EXPECT_EQ(back->virtual_objects[0].placement.scale, scene->virtual_objects[0].placement.scale);
  ASSERT_EQ(back->lights.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->lights[i].type, scene->lights[i].type);
    EXPECT_EQ(back->lights[i].real, scene->lights[i].real);
    EXPECT_EQ(back->lights[i].position, scene->lights[i].position);
    EXPECT_EQ(back->lights[i].direction, scene->lights[i].direction);
    EXPECT_EQ(back->lights[i].color, scene->lights[i].color);
    EXPECT_EQ(back->lights[i].intensity, scene->lights[i].intensity);
    EXPECT_EQ(back->lights[i].inner_angle_deg, scene->lights[i].inner_angle_deg);
  }
  EXPECT_EQ(back->environment.image, scene->environment.image);
  // Keyframed motion round-trips too.
  SceneDesc moving = *scene;
  moving.virtual_objects[0].motion = {{0.0, moving.virtual_objects[0].placement}, {0.5, moving.virtual_objects[0].placement}};
  moving.virtual_objects[0].motion[1].placement.position = glm::vec3(1.0f, 2.0f, 3.0f);
  ASSERT_TRUE(write_scene_json(f.dir.file("out/moving.json"), moving).ok());
  auto moved = load_scene_json(f.dir.file("out/moving.json"));
  ASSERT_TRUE(moved.ok()) << moved.error().message;
  ASSERT_EQ(moved->virtual_objects[0].motion.size(), 2u);
  EXPECT_EQ(moved->virtual_objects[0].motion[1].time_s, 0.5);
  EXPECT_EQ(moved->virtual_objects[0].motion[1].placement.position, glm::vec3(1.0f, 2.0f, 3.0f));
  // And a lamp's: position, direction and intensity per key; lamp_at interpolates them.
  SceneDesc lit = *scene;
  ASSERT_EQ(lit.lights[0].type, LightType::Point);
  LampKey k0{0.0, glm::vec3(0.0f, 2.0f, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f), 1.0f};
  LampKey k1{1.0, glm::vec3(1.0f, 2.0f, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f), 0.0f};
  lit.lights[0].motion = {k0, k1};
  ASSERT_TRUE(write_scene_json(f.dir.file("out/lit.json"), lit).ok());
  auto lit_back = load_scene_json(f.dir.file("out/lit.json"));
  ASSERT_TRUE(lit_back.ok()) << lit_back.error().message;
  ASSERT_EQ(lit_back->lights[0].motion.size(), 2u);
  EXPECT_EQ(lit_back->lights[0].motion[1].position, glm::vec3(1.0f, 2.0f, 0.0f));
  EXPECT_EQ(lit_back->lights[0].motion[1].intensity, 0.0f);
  const LightDesc mid = lamp_at(lit_back->lights[0], 0.25);
  EXPECT_NEAR(mid.position.x, 0.25f, 1e-6f);
  EXPECT_NEAR(mid.intensity, 0.75f, 1e-6f);
  EXPECT_TRUE(mid.motion.empty());
  EXPECT_EQ(lamp_at(lit_back->lights[0], -5.0).position, k0.position);  // held outside the keys
  EXPECT_EQ(lamp_at(lit_back->lights[0], 9.0).intensity, 0.0f);
  EXPECT_EQ(back->environment.intensity, scene->environment.intensity);
  EXPECT_EQ(back->real_geometry[0].material.base_color, scene->real_geometry[0].material.base_color);
  ASSERT_EQ(back->real_materials.size(), 1u);
  EXPECT_EQ(back->real_materials[0].max, scene->real_materials[0].max);
  EXPECT_EQ(back->real_materials[0].roughness, scene->real_materials[0].roughness);
}

TEST(SceneJson, DefaultsForOptionalKeys) {
  SceneFixture f;
  auto scene = load_scene_json(f.write(R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb"}],
      "environment": {"from_env_camera": true}})"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->virtual_objects[0].placement.scale, glm::vec3(1.0f));
  EXPECT_EQ(scene->virtual_objects[0].placement.rotation, glm::quat(1, 0, 0, 0));
  EXPECT_TRUE(scene->environment.from_env_camera);
  EXPECT_TRUE(scene->environment.image.empty());
  EXPECT_TRUE(scene->lights.empty());
}

struct BadScene {
  const char* json;
  ErrorKind kind;
  const char* key;   // JSON path the message must name
  const char* rule;  // words of the rule the message must give
};

// What gtest prints for a case (not its bytes, which hold pointers).
void PrintTo(const BadScene& c, std::ostream* os) { *os << c.key << ": " << c.json; }

class SceneJsonRefuses : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneJsonRefuses, NamingFileKeyAndRule) {
  SceneFixture f;
  const BadScene& bad = GetParam();
  auto path = f.write(bad.json);
  auto scene = load_scene_json(path);
  ASSERT_FALSE(scene.ok()) << bad.json;
  EXPECT_EQ(scene.error().kind, bad.kind) << scene.error().message;
  const std::string& msg = scene.error().message;
  EXPECT_TRUE(testing::contains(msg, path)) << msg;
  EXPECT_TRUE(testing::contains(msg, bad.key)) << msg;
  EXPECT_TRUE(testing::contains(msg, bad.rule)) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SceneJsonRefuses,
    ::testing::Values(
        BadScene{R"({"version": 1, "virtual_object": []})", ErrorKind::BadInput, "virtual_object", "unknown key"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0], "colour": [1,1,1]}]})",
                 ErrorKind::BadInput, "lights[0].colour", "unknown key"},
        BadScene{R"({"virtual_objects": []})", ErrorKind::BadInput, "version", "required key is missing"},
        BadScene{R"({"version": 2})", ErrorKind::BadInput, "version", "unsupported"},
        BadScene{R"({"version": "1"})", ErrorKind::BadInput, "version", "must be an integer, got a string"},
        BadScene{R"({"version": 1, "virtual_objects": {}})", ErrorKind::BadInput, "virtual_objects", "must be an array"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": 3}]})", ErrorKind::BadInput,
                 "virtual_objects[0].gltf", "must be a string"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/none.glb"}]})", ErrorKind::NotFound,
                 "virtual_objects[0].gltf", "does not exist"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "motion": [{"time": 0.5}, {"time": 0.5}]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].motion", "increase strictly"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "motion": [{"position": [0, 0, 0]}]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].motion[0].time", "required key is missing"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "motion": [{"time": 0, "scale": -1}]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].motion[0].scale", "must be positive"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0, 1, 0], "motion": [{"time": 1}, {"time": 0}]}]})",
                 ErrorKind::BadInput, "lights[0].motion", "increase strictly"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0, 1, 0], "motion": [{"time": 0, "direction": [0, -1, 0]}]}]})",
                 ErrorKind::BadInput, "lights[0].motion[0].direction", "point light has no direction"},
        BadScene{R"({"version": 1, "lights": [{"type": "spot", "real": true, "position": [0, 1, 0], "direction": [0, -1, 0], "motion": [{"time": 0, "direction": [0, 0, 0]}]}]})",
                 ErrorKind::BadInput, "lights[0].motion[0].direction", "non-zero"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0, 1, 0], "motion": [{"time": 0, "intensity": -2}]}]})",
                 ErrorKind::BadInput, "lights[0].motion[0].intensity", ">= 0"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "motion": [{"time": 0, "speed": 1}]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].motion[0].speed", "unknown key"},
        BadScene{R"({"version": 1, "real_materials": [{"min": [0, 0, 0], "max": [1, -1, 1]}]})", ErrorKind::BadInput,
                 "max", "must be >= min"},
        BadScene{R"({"version": 1, "real_materials": [{"min": [0, 0, 0], "max": [1, 1, 1], "roughness": 2}]})",
                 ErrorKind::BadInput, "roughness", "must be in [0.000000, 1.000000]"},
        BadScene{R"({"version": 1, "real_materials": [{"max": [1, 1, 1]}]})", ErrorKind::BadInput, "min",
                 "required key is missing"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "position": [1, 2]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].position", "array of 3 numbers, got an array of 2"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "position": [1, "a", 2]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].position[1]", "must be a number"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "position": [1, 1e999, 2]}]})",
                 ErrorKind::BadInput, "1e999", "number overflow"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "rotation": [0, 0, 0, 2]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].rotation", "unit length (within 0.001)"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "scale": [1, 0, 1]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].scale", "positive"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "scale": "big"}]})",
                 ErrorKind::BadInput, "virtual_objects[0].scale", "a number (uniform) or an array of 3"},
        BadScene{R"({"version": 1, "lights": [{"type": "area", "real": true}]})", ErrorKind::BadInput,
                 "lights[0].type", "\"point\", \"spot\" or \"directional\""},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "position": [0,0,0]}]})", ErrorKind::BadInput,
                 "lights[0].real", "required key is missing"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0], "intensity": -1}]})",
                 ErrorKind::BadInput, "lights[0].intensity", ">= 0"},
        BadScene{R"({"version": 1, "lights": [{"type": "directional", "real": true, "direction": [0,0,0]}]})",
                 ErrorKind::BadInput, "lights[0].direction", "non-zero"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0]},
                   {"type": "spot", "real": true, "position": [0,0,0], "direction": [0,-1,0],
                    "inner_angle_deg": 50, "outer_angle_deg": 40}]})",
                 ErrorKind::BadInput, "lights[1].inner_angle_deg", "must not exceed outer_angle_deg"},
        BadScene{R"({"version": 1, "lights": [{"type": "spot", "real": true, "position": [0,0,0],
                    "direction": [0,-1,0], "outer_angle_deg": 90}]})",
                 ErrorKind::BadInput, "lights[0].outer_angle_deg", "(0, 90)"},
        BadScene{R"({"version": 1, "lights": [{"type": "directional", "real": true, "direction": [0,-1,0],
                    "position": [0,0,0]}]})",
                 ErrorKind::BadInput, "lights[0].position", "no position"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0],
                    "outer_angle_deg": 30}]})",
                 ErrorKind::BadInput, "lights[0].outer_angle_deg", "spot lights only"},
        BadScene{R"({"version": 1, "environment": {"image": "env/sky.exr", "from_env_camera": true}})",
                 ErrorKind::BadInput, "environment.image", "exactly one"},
        BadScene{R"({"version": 1, "environment": {"real": 1}})", ErrorKind::BadInput, "environment.real",
                 "true or false"},
        BadScene{R"({"version": 1, "real_geometry": [{"gltf": "models/box.glb", "material": {"roughness": 2}}]})",
                 ErrorKind::BadInput, "real_geometry[0].material.roughness", "[0.000000, 1.000000]"},
        BadScene{R"({"version": 1, "real_geometry": [{"gltf": "models/box.glb", "material": {"shiny": 1}}]})",
                 ErrorKind::BadInput, "real_geometry[0].material.shiny", "unknown key"},
        BadScene{"{\"version\": 1,\n  \"lights\": [,]}", ErrorKind::BadInput, "line 2", "invalid JSON"},
        BadScene{R"([1, 2])", ErrorKind::BadInput, "top level", "must be an object"},
        // A repeated key (JSON keeps the last one silently) and numbers finite as doubles but
        // infinite as the floats they end up in.
        BadScene{R"({"version": 1, "version": 1})", ErrorKind::BadInput, "'version'", "appears twice"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0]},
                   {"type": "point", "real": true, "real": false, "position": [0,0,0]}]})",
                 ErrorKind::BadInput, "'real' appears twice in 'lights[]'", "each key once"},
        BadScene{R"({"version": 1, "lights": [{"type": "point", "real": true, "position": [0,0,0], "intensity": 1e39}]})",
                 ErrorKind::BadInput, "lights[0].intensity", "32-bit float"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "scale": 1e39}]})",
                 ErrorKind::BadInput, "virtual_objects[0].scale", "32-bit float"},
        BadScene{R"({"version": 1, "virtual_objects": [{"gltf": "models/box.glb", "position": [0, -1e39, 0]}]})",
                 ErrorKind::BadInput, "virtual_objects[0].position[1]", "32-bit float"}),
    // Names from the case's index and the key it names: stable across builds (the default
    // printed the struct's bytes, pointers included).
    [](const ::testing::TestParamInfo<BadScene>& info) {
      std::string name = std::to_string(info.index) + "_";
      for (const char* c = info.param.key; *c; ++c)
        name += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
      return name;
    });

// The same key in different objects is fine.
TEST(SceneJson, SameKeyInDifferentObjectsIsAccepted) {
  SceneFixture f;
  auto scene = load_scene_json(f.write(R"({"version": 1, "lights": [
    {"type": "point", "real": true, "position": [0, 2, 0]},
    {"type": "point", "real": false, "position": [1, 2, 0]}]})"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->lights.size(), 2u);
}

TEST(SceneJson, MissingFileIsNotFound) {
  TempDir dir;
  EXPECT_ERROR(load_scene_json(dir.file("scene.json")), NotFound, "scene.json");
}

TEST(Placement, MatrixAppliesScaleThenRotationThenTranslation) {
  Placement p;
  p.position = {1, 2, 3};
  p.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  p.scale = glm::vec3(2.0f);
  const glm::vec4 x = p.matrix() * glm::vec4(1, 0, 0, 1);  // +x scaled to 2, turned to -z
  EXPECT_NEAR(x.x, 1.0f, 1e-5f);
  EXPECT_NEAR(x.y, 2.0f, 1e-5f);
  EXPECT_NEAR(x.z, 1.0f, 1e-5f);
}

}  // namespace
}  // namespace mrgi
