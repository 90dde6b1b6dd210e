#include <gtest/gtest.h>

#include <cctype>
#include <ostream>

#include "capture/temp_dir.h"
#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

using testing::TempDir;
using testing::write_text;

TEST(CaptureJson, ParsesEveryKey) {
  TempDir dir;
  write_text(dir.file("capture.json"), R"({
    "version": 1,
    "color": {"width": 320, "height": 240, "fx": 260, "fy": 261, "cx": 160.5, "cy": 120.5},
    "depth": {"width": 160, "height": 120, "fx": 130, "fy": 131, "cx": 80, "cy": 60},
    "depth_scale": 1000, "exposure": 2.5,
    "env_camera": {"model": "fisheye_equidistant", "f": 300, "cx": 512, "cy": 512, "fov_deg": 190,
                   "rotation": [0, 0, 0, 1]},
    "apriltag": {"family": "tag36h11", "size_m": 0.16,
                 "tags": [{"id": 3, "position": [1, 0, 2], "rotation": [0, 0, 0, 1]}]}
  })");
  auto info = load_capture_json(dir.file("capture.json"));
  ASSERT_TRUE(info.ok()) << info.error().message;
  EXPECT_EQ(info->color.width, 320);
  EXPECT_DOUBLE_EQ(info->color.cx, 160.5);
  EXPECT_EQ(info->depth.height, 120);
  EXPECT_DOUBLE_EQ(info->depth.fy, 131);
  EXPECT_DOUBLE_EQ(info->depth_scale, 1000);
  EXPECT_DOUBLE_EQ(info->exposure, 2.5);
  ASSERT_TRUE(info->env_camera.has_value());
  EXPECT_EQ(info->env_camera->model, EnvModel::FisheyeEquidistant);
  EXPECT_DOUBLE_EQ(info->env_camera->fov_deg, 190);
  ASSERT_TRUE(info->apriltag.has_value());
  EXPECT_DOUBLE_EQ(info->apriltag->size_m, 0.16);
  ASSERT_EQ(info->apriltag->tags.size(), 1u);
  EXPECT_EQ(info->apriltag->tags[0].id, 3);
  EXPECT_DOUBLE_EQ(info->apriltag->tags[0].tag_to_world.translation.z, 2);
}

TEST(CaptureJson, DepthDefaultsToColourAndWriteRoundTrips) {
  TempDir dir;
  write_text(dir.file("capture.json"), R"({"version": 1,
    "color": {"width": 64, "height": 48, "fx": 51.7, "fy": 51.6, "cx": 31.8, "cy": 25.5},
    "env_camera": {"model": "equirectangular", "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476]}})");
  auto info = load_capture_json(dir.file("capture.json"));
  ASSERT_TRUE(info.ok()) << info.error().message;
  EXPECT_EQ(info->depth.width, 64);
  EXPECT_DOUBLE_EQ(info->depth.fx, 51.7);
  EXPECT_DOUBLE_EQ(info->depth_scale, 5000);  // TUM default
  ASSERT_TRUE(write_capture_json(dir.file("out.json"), *info).ok());
  auto back = load_capture_json(dir.file("out.json"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->color.fx, info->color.fx);
  EXPECT_EQ(back->depth.cy, info->depth.cy);
  EXPECT_EQ(back->env_camera->rotation, info->env_camera->rotation);
  EXPECT_FALSE(back->apriltag.has_value());
}

struct BadCaptureJson {
  const char* json;
  const char* key;
  const char* rule;
};

// What gtest prints for a case (not its bytes, which hold pointers).
void PrintTo(const BadCaptureJson& c, std::ostream* os) { *os << c.key << ": " << c.json; }

class CaptureJsonRefuses : public ::testing::TestWithParam<BadCaptureJson> {};

TEST_P(CaptureJsonRefuses, NamingFileKeyAndRule) {
  TempDir dir;
  write_text(dir.file("capture.json"), GetParam().json);
  auto info = load_capture_json(dir.file("capture.json"));
  ASSERT_FALSE(info.ok()) << GetParam().json;
  EXPECT_EQ(info.error().kind, ErrorKind::BadInput);
  const std::string& msg = info.error().message;
  EXPECT_TRUE(testing::contains(msg, dir.file("capture.json"))) << msg;
  EXPECT_TRUE(testing::contains(msg, GetParam().key)) << msg;
  EXPECT_TRUE(testing::contains(msg, GetParam().rule)) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CaptureJsonRefuses,
    ::testing::Values(
        BadCaptureJson{R"({"version": 1, "depth_scale": 5000, "fps": 30})", "fps", "unknown key"},
        BadCaptureJson{R"({"depth_scale": 5000})", "version", "required key is missing"},
        BadCaptureJson{R"({"version": 1, "depth_scale": "5000"})", "depth_scale", "must be a number, got a string"},
        BadCaptureJson{R"({"version": 1, "depth_scale": 0})", "depth_scale", "> 0"},
        BadCaptureJson{R"({"version": 1, "exposure": -1})", "exposure", "> 0"},
        BadCaptureJson{R"({"version": 1, "color": {"width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 32}})",
                       "color.cy", "required key is missing"},
        BadCaptureJson{R"({"version": 1, "color": {"width": 64.5, "height": 48, "fx": 50, "fy": 50, "cx": 32, "cy": 24}})",
                       "color.width", "must be an integer"},
        BadCaptureJson{R"({"version": 1, "depth": {"width": 64, "height": 48, "fx": 0, "fy": 50, "cx": 32, "cy": 24}})",
                       "depth.fx", "> 0 pixels"},
        BadCaptureJson{R"({"version": 1, "color": [640, 480]})", "color", "must be an object"},
        BadCaptureJson{R"({"version": 1, "env_camera": {"model": "cubemap"}})", "env_camera.model",
                       "\"equirectangular\" or \"fisheye_equidistant\""},
        BadCaptureJson{R"({"version": 1, "env_camera": {"model": "fisheye_equidistant", "cx": 1, "cy": 1}})",
                       "env_camera.f", "required key is missing"},
        BadCaptureJson{R"({"version": 1, "env_camera": {"model": "equirectangular", "f": 100}})",
                       "env_camera.f", "fisheye_equidistant\" only"},
        BadCaptureJson{R"({"version": 1, "env_camera": {"model": "equirectangular", "rotation": [0, 0, 0.5, 0.5]}})",
                       "env_camera.rotation", "unit length"},
        BadCaptureJson{R"({"version": 1, "apriltag": {"family": "tag99h1"}})", "apriltag.family",
                       "unknown AprilTag family"},
        BadCaptureJson{R"({"version": 1, "apriltag": {"tags": [{"id": 1, "position": [0,0,0], "rotation": [0,0,0,1]},
                                                         {"id": 1, "position": [0,0,0], "rotation": [0,0,0,1]}]}})",
                       "apriltag.tags[1].id", "listed twice"},
        BadCaptureJson{R"({"version": 1, "apriltag": {"tags": [{"id": 1, "position": [0,0], "rotation": [0,0,0,1]}]}})",
                       "apriltag.tags[0].position", "array of 3 numbers"}),
    // Names from the case's index and the key it names: stable across builds (the default
    // printed the struct's bytes, pointers included).
    [](const ::testing::TestParamInfo<BadCaptureJson>& info) {
      std::string name = std::to_string(info.index) + "_";
      for (const char* c = info.param.key; *c; ++c)
        name += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
      return name;
    });

}  // namespace
}  // namespace mrgi
