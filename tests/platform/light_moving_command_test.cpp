// `mrgi light-moving` end to end on a tiny moving-camera family rendered here by `mrgi synth`: a
// 6-frame sweep and a lamp-switch pair joined by perf/suite/light/splice_switch.py; every figure
// the report promises is there, and a family that was never rendered is refused in words.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace mrgi {
namespace {

nlohmann::json description(int frames, bool lamp_on, double sweep_deg) {
  nlohmann::json path = nlohmann::json::array();
  for (int i = 0; i < frames; ++i) {
    const double a = (-20.0 + sweep_deg * i / std::max(1, frames - 1)) * 3.14159265358979 / 180.0;
    path.push_back({{"time", i / 30.0}, {"position", {1.2 * std::sin(a), 1.2, 0.35 - 1.2 * std::cos(a)}},
                    {"look_at", {0.0, 0.6, 0.35}}});
  }
  nlohmann::json lights = nlohmann::json::array(
      {{{"type", "point"}, {"position", {0.5, 1.5, 0.0}}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 2.0}}});
  if (lamp_on)
    lights.push_back({{"type", "point"}, {"position", {-0.6, 1.4, 0.2}}, {"color", {1, 1, 1}}, {"intensity", 3.0}});
  return {{"version", 1},
          {"frames", frames},
          {"camera", {{"width", 64}, {"height", 48}, {"fx", 52.5}, {"fy", 52.5}}},
          {"camera_path", path},
          {"render", {{"spp", 8}, {"max_depth", 2}, {"seed", 5}}},
          {"real_objects",
           {{{"shape", "plane"}, {"size", {4, 4}}, {"material", {{"color", {0.5, 0.5, 0.5}}}}},
            {{"shape", "box"}, {"size", {0.8, 0.04, 0.6}}, {"position", {0, 0.58, 0.35}},
             {"material", {{"color", {0.6, 0.5, 0.4}}}}}}},
          {"lights", lights},
          {"virtual_objects",
           {{{"gltf", std::string(MRGI_SOURCE_DIR) + "/perf/suite/assets/white_box.gltf"}, {"position", {0, 0.6, 0.35}},
             {"scale", 0.5}}}},
          {"depth_sensor", {{"depth_scale", 5000}}},
          {"light_probe", {{"width", 16}, {"spp", 16}}}};
}

class LightMovingCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  }
};

TEST_F(LightMovingCommand, ReportsTheSweepTheSwitchAndTheDriftAndRefusesAnUnrenderedFamily) {
  test::TempDir dir("light-moving");
  const std::string tool = std::string("timeout 300 ") + MRGI_TOOL;
  for (const auto& [name, frames, on, sweep] :
       {std::tuple{"sweep", 6, false, 90.0}, std::tuple{"off", 2, false, 0.5}, std::tuple{"on", 2, true, 0.5}}) {
    std::ofstream(dir.file(std::string(name) + ".json")) << description(frames, on, sweep).dump(1);
    ASSERT_EQ(test::run_command(tool + " synth " + dir.file(std::string(name) + ".json") + " --out " +
                                dir.file(name) + " --threads 2 > " + dir.file("synth.txt") + " 2>&1"),
              0)
        << test::read_text(dir.file("synth.txt"));
  }
  const nlohmann::json manifest = {
      {"version", 1},
      {"scenes", {{{"name", "sweep"}, {"capture", "sweep"}, {"held_out", false}}}},
      {"switches",
       {{{"name", "lamp_switch"}, {"off", dir.file("off")}, {"on", dir.file("on")}, {"capture", dir.file("switch")},
         {"held_out", false}}}}};
  std::ofstream(dir.file("family.json")) << manifest.dump(1);
  ASSERT_EQ(test::run_command("python3 " + std::string(MRGI_SOURCE_DIR) + "/perf/suite/light/splice_switch.py " +
                              dir.file("family.json") + " --at 10 --frames 30 > " + dir.file("splice.txt") + " 2>&1"),
            0)
      << test::read_text(dir.file("splice.txt"));
  ASSERT_EQ(test::run_command(tool + " light-moving --manifest " + dir.file("family.json") + " --root " + dir.path.string() +
                              " --level lowest --drift-frames 24 -o " + dir.file("out") + " > " + dir.file("run.txt") +
                              " 2>&1"),
            0)
      << test::read_text(dir.file("run.txt"));
  const auto j = nlohmann::json::parse(test::read_text(dir.file("out/light-moving.json")));
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scenes"][0]["frames"].size(), 6u);
  for (const auto& f : j["scenes"][0]["frames"]) {
    EXPECT_TRUE(std::isfinite(f["direction_error_deg"].get<double>()));
    EXPECT_GT(f["rde_true"].get<double>(), 0.0);
  }
  ASSERT_EQ(j["switches"].size(), 1u);
  EXPECT_EQ(j["switches"][0]["at"].get<int>(), 10);
  ASSERT_EQ(j["drift"].size(), 1u);
  EXPECT_EQ(j["drift"][0]["frames"].get<int>(), 24);
  const std::string md = test::read_text(dir.file("out/light-moving.md"));
  for (const char* k : {"as the sweep grows", "A lamp switched on", "Drift:"}) EXPECT_NE(md.find(k), std::string::npos) << k;

  // A family whose captures were never rendered: refused, naming the folder and the command.
  std::filesystem::remove_all(dir.file("sweep"));
  EXPECT_NE(test::run_command(tool + " light-moving --manifest " + dir.file("family.json") + " --root " + dir.path.string() +
                              " --no-switches > " + dir.file("err.txt") + " 2>&1"),
            0);
  const std::string err = test::read_text(dir.file("err.txt"));
  EXPECT_NE(err.find("not rendered"), std::string::npos) << err;
  EXPECT_NE(err.find("render_moving_family.sh"), std::string::npos) << err;
}

}  // namespace
}  // namespace mrgi
