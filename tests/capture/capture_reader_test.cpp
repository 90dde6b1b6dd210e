#include <gtest/gtest.h>

#include <sys/stat.h>
#include <png.h>

#include <filesystem>

#include "capture/capture_fixture.h"
#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

using testing::CaptureFixture;
using testing::kH;
using testing::kW;
using testing::write_text;

TEST(CaptureReader, OpensAndReadsFramesInOrder) {
  CaptureFixture f(3);
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->frame_count(), 3u);
  EXPECT_EQ(reader->dropped_color_frames(), 0u);
  EXPECT_FALSE(reader->scene().has_value());
  EXPECT_FALSE(reader->has_references());
  auto frame = reader->read_frame(2);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_EQ(frame->index, 2);
  EXPECT_DOUBLE_EQ(frame->timestamp, 1.2);
  EXPECT_EQ(frame->color.data, testing::test_color(kW, kH, 2).data);
  EXPECT_EQ(frame->depth.data, testing::test_depth(kW, kH, 2).data);
  EXPECT_FALSE(frame->pose.has_value());
  EXPECT_FALSE(frame->env.has_value());
  EXPECT_ERROR(reader->read_frame(3), BadUsage, "frame 3 does not exist");
}

TEST(CaptureReader, TumFreiburg1DefaultsWithoutCaptureJson) {
  CaptureFixture f(1);
  std::filesystem::remove(f.file("capture.json"));
  ASSERT_TRUE(write_png(f.file("rgb/0.png"), ImageRGB8(640, 480, 7)).ok());
  ASSERT_TRUE(write_png(f.file("depth/0.png"), ImageU16(640, 480, 5000)).ok());
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  const CaptureInfo& info = reader->info();
  EXPECT_EQ(info.color.width, 640);
  EXPECT_EQ(info.color.height, 480);
  EXPECT_DOUBLE_EQ(info.color.fx, 517.3);
  EXPECT_DOUBLE_EQ(info.color.fy, 516.5);
  EXPECT_DOUBLE_EQ(info.color.cx, 318.6);
  EXPECT_DOUBLE_EQ(info.color.cy, 255.3);
  EXPECT_EQ(info.depth.width, 640);
  EXPECT_DOUBLE_EQ(info.depth_scale, 5000.0);
  EXPECT_DOUBLE_EQ(info.exposure, 1.0);
  EXPECT_FALSE(info.env_camera.has_value());
  EXPECT_FALSE(info.apriltag.has_value());
}

TEST(CaptureReader, AssociatesDepthByNearestTimestampAndDropsUnmatchedColour) {
  CaptureFixture f(4);
  // Colour at 1.0 1.1 1.2 1.3; depth near 1.0 (0.005 off), 1.2 (0.019 off) and far from the rest.
  write_text(f.file("depth.txt"), "1.005 depth/0.png\n1.219 depth/1.png\n1.5 depth/2.png\n");
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->frame_count(), 2u);
  EXPECT_EQ(reader->dropped_color_frames(), 2u);
  EXPECT_DOUBLE_EQ(reader->entry(0).timestamp, 1.0);
  EXPECT_DOUBLE_EQ(reader->entry(0).depth_timestamp, 1.005);
  EXPECT_DOUBLE_EQ(reader->entry(1).timestamp, 1.2);
  EXPECT_TRUE(testing::contains(reader->entry(1).depth, "depth/1.png"));
}

TEST(CaptureReader, EachDepthFrameIsUsedOnce) {
  CaptureFixture f(2);
  // Colour 1.0 and 1.1 (0.1 apart) cannot share; with colour 1.0/1.01 and one depth at 1.008,
  // only the closer colour frame (1.01) gets it.
  write_text(f.file("rgb.txt"), "1.0 rgb/0.png\n1.01 rgb/1.png\n");
  write_text(f.file("depth.txt"), "1.008 depth/0.png\n");
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->frame_count(), 1u);
  EXPECT_DOUBLE_EQ(reader->entry(0).timestamp, 1.01);
}

TEST(CaptureReader, PosesInterpolatedAtColourTimestamps) {
  CaptureFixture f(3);
  // Colour at 1.0, 1.1, 1.2. Poses at 0.95 and 1.15: frame 1.0 is interpolated (u = 1/4 of a
  // 90 deg turn about y), frame 1.1 too (u = 3/4), frame 1.2 is 0.05 s past the end: no pose.
  write_text(f.file("groundtruth.txt"),
             "# timestamp tx ty tz qx qy qz qw\n0.95 0 0 0 0 0 0 1\n1.15 4 0 0 0 0.70710678 0 0.70710678\n");
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_TRUE(reader->entry(0).pose.has_value());
  const Pose& p = *reader->entry(0).pose;
  EXPECT_NEAR(p.translation.x, 1.0, 1e-9);
  const double angle = glm::angle(p.rotation);
  EXPECT_NEAR(angle, glm::radians(22.5), 1e-6);
  EXPECT_NEAR(reader->entry(1).pose->translation.x, 3.0, 1e-9);
  EXPECT_FALSE(reader->entry(2).pose.has_value());
}

TEST(CaptureReader, EnvImagesNearestInTime) {
  CaptureFixture f(3);
  ImageRGBF env(4, 2, 0.25f);
  ASSERT_TRUE(write_exr(f.file("env/a.exr"), env).ok());
  env.data[0] = 2.0f;
  ASSERT_TRUE(write_exr(f.file("env/b.exr"), env).ok());
  write_text(f.file("env.txt"), "0.9 env/a.exr\n1.16 env/b.exr\n");
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_TRUE(testing::contains(reader->entry(0).env, "a.exr"));
  EXPECT_TRUE(testing::contains(reader->entry(1).env, "b.exr"));  // 1.1 is nearer 1.16 than 0.9
  auto frame = reader->read_frame(2);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  ASSERT_TRUE(frame->env.has_value());
  EXPECT_EQ(frame->env->data[0], 2.0f);
}

// ---- Refusals: each names the file, the line or key, and the rule. -----------------------

TEST(CaptureRefuses, MissingFolderOrRgbList) {
  CaptureFixture f(1);
  EXPECT_ERROR(CaptureReader::open(f.dir.file("nope")), NotFound, "nope", "does not exist");
  std::filesystem::remove(f.file("rgb.txt"));
  EXPECT_ERROR(CaptureReader::open(f.folder()), NotFound, "rgb.txt", "missing", "needs rgb.txt and depth.txt");
}

TEST(CaptureRefuses, ListedPngAbsent) {
  CaptureFixture f(3);
  std::filesystem::remove(f.file("rgb/2.png"));
  EXPECT_ERROR(CaptureReader::open(f.folder()), NotFound, "rgb.txt:4:", "'rgb/2.png'", "does not exist");
}

TEST(CaptureRefuses, LineWithTooFewOrTooManyFields) {
  CaptureFixture f(2);
  write_text(f.file("rgb.txt"), "1.0 rgb/0.png\n1.1\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb.txt:2:", "expected 'timestamp path', got 1 field");
  write_text(f.file("rgb.txt"), "\n# comment\n1.0 rgb/0.png\n1.1 rgb/1.png extra\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb.txt:4:", "expected 'timestamp path', got 3 fields");
}

// A NUL byte inside a listed path (it would name another file where the
// file system reads it) and a list that is a FIFO (opening it would block for ever).
TEST(CaptureRefuses, NulByteInAListedPathAndAFifoList) {
  CaptureFixture f(2);
  write_text(f.file("rgb.txt"), std::string("1.0 rgb/0.png\n1.1 rgb/1.png\0.evil\n", 34));
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb.txt:2:", "NUL byte");
  std::filesystem::remove(f.file("depth.txt"));
  ASSERT_EQ(mkfifo(f.file("depth.txt").c_str(), 0600), 0);
  write_text(f.file("rgb.txt"), "1.0 rgb/0.png\n1.1 rgb/1.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "depth.txt", "regular file");  // refused, not opened
}

TEST(CaptureRefuses, NonNumericTimestamp) {
  CaptureFixture f(2);
  write_text(f.file("depth.txt"), "1.0 depth/0.png\n1.1s depth/1.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "depth.txt:2:", "'1.1s'", "not a finite number");
}

TEST(CaptureRefuses, DecreasingOrRepeatedTimestamps) {
  CaptureFixture f(3);
  write_text(f.file("rgb.txt"), "1.0 rgb/0.png\n1.2 rgb/1.png\n1.1 rgb/2.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb.txt:3:", "not after line 2", "strictly increase");
  write_text(f.file("rgb.txt"), "1.0 rgb/0.png\n1.0 rgb/1.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb.txt:2:", "strictly increase");
}

TEST(CaptureRefuses, WrongImageSizeOnFirstOrLaterFrame) {
  CaptureFixture f(3);
  ASSERT_TRUE(write_png(f.file("rgb/0.png"), testing::test_color(kW + 2, kH, 0)).ok());
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb/0.png", "image is 10x6", "expected 8x6",
               "colour intrinsics");
  ASSERT_TRUE(write_png(f.file("rgb/0.png"), testing::test_color(kW, kH, 0)).ok());
  ASSERT_TRUE(write_png(f.file("depth/2.png"), testing::test_depth(kW, kH + 1, 0)).ok());
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;  // open() checks the first frame only
  EXPECT_ERROR(reader->read_frame(2), BadInput, "depth/2.png", "image is 8x7", "expected 8x6", "depth intrinsics");
}

TEST(CaptureRefuses, EightBitDepthPng) {
  CaptureFixture f(1);
  ASSERT_TRUE(write_png(f.file("depth/0.png"), ImageU8(kW, kH, 200)).ok());
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "depth/0.png", "PNG is 8-bit grey",
               "expected 16-bit grey");
}

TEST(CaptureRefuses, SixteenBitColourPng) {
  CaptureFixture f(1);
  // libpng's simplified writer makes a real 16-bit RGB file (our writer has no such format).
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = kW;
  image.height = kH;
  image.format = PNG_FORMAT_LINEAR_RGB;
  std::vector<uint16_t> pixels(size_t(kW) * kH * 3, 30000);
  ASSERT_TRUE(png_image_write_to_file(&image, f.file("rgb/0.png").c_str(), 0, pixels.data(), 0, nullptr));
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "rgb/0.png", "PNG is 16-bit RGB",
               "expected 8-bit RGB");
}

TEST(CaptureRefuses, NoDepthMatchesAnyColourFrame) {
  CaptureFixture f(2);
  write_text(f.file("depth.txt"), "5.0 depth/0.png\n6.0 depth/1.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "depth.txt", "within 0.02 s");
}

TEST(CaptureRefuses, NanInGroundtruth) {
  CaptureFixture f(2);
  write_text(f.file("groundtruth.txt"), "1.0 0 0 0 0 0 0 1\n1.1 0 nan 0 0 0 0 1\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "groundtruth.txt:2:", "ty 'nan'", "not a finite number");
}

TEST(CaptureRefuses, GroundtruthLineWithSevenNumbers) {
  CaptureFixture f(2);
  write_text(f.file("groundtruth.txt"), "1.0 0 0 0 0 0 1\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "groundtruth.txt:1:",
               "expected 'timestamp tx ty tz qx qy qz qw', got 7 fields");
}

TEST(CaptureRefuses, NonUnitQuaternion) {
  CaptureFixture f(2);
  write_text(f.file("groundtruth.txt"), "# poses\n1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 0 1.01\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "groundtruth.txt:3:", "length 1.01",
               "unit length within 0.001");
}

TEST(CaptureRefuses, ReferenceWithoutColourFrame) {
  CaptureFixture f(2);
  ASSERT_TRUE(write_png(f.file("reference/0.png"), testing::test_color(kW, kH, 9)).ok());
  write_text(f.file("reference.txt"), "1.0 reference/0.png\n3.0 reference/0.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "reference.txt:2:", "no colour frame", "0.02 s");
}

TEST(CaptureRefuses, BadCaptureJsonAndSceneJson) {
  CaptureFixture f(1);
  write_text(f.file("capture.json"), R"({"version": 1, "colour": {}})");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "capture.json", "colour", "unknown key");
  write_text(f.file("capture.json"), testing::capture_json(kW, kH));
  write_text(f.file("scene.json"), R"({"version": 1, "lights": [{"type": "point", "real": "yes"}]})");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "scene.json", "lights[0].real", "true or false");
}

// scene.json's environment from the env camera needs the camera (capture.json env_camera) and
// its images (env.txt): without either it would light nothing, so the capture is refused naming
// what is missing; with both it opens.
TEST(CaptureRefuses, EnvironmentFromEnvCameraWithoutTheCameraOrItsImages) {
  CaptureFixture f(1);
  write_text(f.file("scene.json"), R"({"version": 1, "environment": {"from_env_camera": true}})");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "scene.json", "environment.from_env_camera",
               "capture.json", "env_camera");
  std::string with_env = testing::capture_json(kW, kH);
  with_env.insert(with_env.size() - 1, R"(, "env_camera": {"model": "equirectangular"})");
  write_text(f.file("capture.json"), with_env);
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "scene.json", "environment.from_env_camera", "env.txt");
  ASSERT_TRUE(write_exr(f.file("env/a.exr"), ImageRGBF(4, 2, 0.25f)).ok());
  write_text(f.file("env.txt"), "1.0 env/a.exr\n");
  auto reader = CaptureReader::open(f.folder());
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_TRUE(reader->scene().has_value());
  EXPECT_TRUE(reader->scene()->environment.from_env_camera);
}

}  // namespace
}  // namespace mrgi
