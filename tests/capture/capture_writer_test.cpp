#include <gtest/gtest.h>

#include <filesystem>

#include "capture/capture_fixture.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_source.h"

namespace mrgi {
namespace {

using testing::kH;
using testing::kW;
using testing::TempDir;

CaptureInfo small_info() {
  CaptureInfo info;
  info.color = Intrinsics{kW, kH, 10.5, 10.25, 3.75, 2.5};
  info.depth = info.color;
  info.depth_scale = 1000;
  info.exposure = 0.75;
  EnvCamera env;
  env.model = EnvModel::FisheyeEquidistant;
  env.f = 2.0;
  env.cx = 2.0;
  env.cy = 1.0;
  info.env_camera = env;
  return info;
}

InputFrame make_frame(int i) {
  InputFrame f;
  f.index = i;
  // Timestamps with many digits, as TUM's: they must come back bit-identical.
  f.timestamp = 1305031102.175304 + 0.0333333 * i;
  f.depth_timestamp = f.timestamp + 0.00123;
  f.color = testing::test_color(kW, kH, i);
  f.depth = testing::test_depth(kW, kH, i);
  Pose p;
  p.translation = {0.1 * i + 1e-7, -0.3333333333, 2.0 / 3.0};
  p.rotation = glm::normalize(glm::dquat(0.9, 0.1 * i, -0.2, 0.3));
  f.pose = p;
  ImageRGBF env(4, 2);
  for (size_t k = 0; k < env.data.size(); ++k) env.data[k] = 0.1f * float(k) + float(i);
  f.env = env;
  return f;
}

TEST(CaptureWriter, RoundTripIsBitIdentical) {
  TempDir dir;
  const std::string folder = dir.file("cap");
  SceneDesc scene;
  testing::write_text(dir.file("assets/obj.glb"), "glb");
  scene.virtual_objects.push_back({dir.file("assets/obj.glb"), Placement{}});
  scene.virtual_objects[0].placement.position = {0.25f, 0.5f, -1.0f};
  auto writer = CaptureWriter::create(folder, small_info(), scene);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  std::vector<InputFrame> frames;
  for (int i = 0; i < 3; ++i) frames.push_back(make_frame(i));
  const ImageRGB8 ref = testing::test_color(kW, kH, 42);
  const ImageU8 mask(kW, kH, 255);
  ASSERT_TRUE(writer->add_frame(frames[0], &ref, &mask).ok());
  ASSERT_TRUE(writer->add_frame(frames[1]).ok());
  ASSERT_TRUE(writer->add_frame(frames[2], &ref).ok());
  // Nothing that looks like a capture exists before finish().
  EXPECT_FALSE(std::filesystem::exists(folder));
  EXPECT_TRUE(std::filesystem::exists(folder + ".partial"));
  ASSERT_TRUE(writer->finish().ok());
  EXPECT_FALSE(std::filesystem::exists(folder + ".partial"));

  auto reader = CaptureReader::open(folder);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->frame_count(), 3u);
  const CaptureInfo& info = reader->info();
  EXPECT_EQ(info.color.fy, 10.25);
  EXPECT_EQ(info.depth_scale, 1000.0);
  EXPECT_EQ(info.exposure, 0.75);
  ASSERT_TRUE(info.env_camera.has_value());
  EXPECT_EQ(info.env_camera->model, EnvModel::FisheyeEquidistant);
  for (size_t i = 0; i < 3; ++i) {
    auto f = reader->read_frame(i);
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ(f->timestamp, frames[i].timestamp);
    EXPECT_EQ(f->depth_timestamp, frames[i].depth_timestamp);
    EXPECT_EQ(f->color.data, frames[i].color.data);
    EXPECT_EQ(f->depth.data, frames[i].depth.data);
    ASSERT_TRUE(f->pose.has_value());
    EXPECT_EQ(f->pose->translation, frames[i].pose->translation);
    EXPECT_EQ(f->pose->rotation, frames[i].pose->rotation);
    ASSERT_TRUE(f->env.has_value());
    EXPECT_EQ(f->env->data, frames[i].env->data);
  }
  EXPECT_TRUE(reader->has_references());
  auto r0 = reader->read_reference(0);
  ASSERT_TRUE(r0.ok()) << r0.error().message;
  EXPECT_EQ(r0->data, ref.data);
  auto m0 = reader->read_reference_mask(0);
  ASSERT_TRUE(m0.ok());
  EXPECT_EQ(m0->data, mask.data);
  EXPECT_ERROR(reader->read_reference(1), NotFound, "frame 1", "no reference image");
  EXPECT_ERROR(reader->read_reference_mask(2), NotFound, "frame 2", "no reference mask");
  ASSERT_TRUE(reader->scene().has_value());
  ASSERT_EQ(reader->scene()->virtual_objects.size(), 1u);
  EXPECT_EQ(std::filesystem::path(reader->scene()->virtual_objects[0].gltf),
            std::filesystem::path(dir.file("assets/obj.glb")));
  EXPECT_EQ(reader->scene()->virtual_objects[0].placement.position, glm::vec3(0.25f, 0.5f, -1.0f));
}

TEST(CaptureWriter, RefusesToOverwriteAndInconsistentFrames) {
  TempDir dir;
  testing::write_text(dir.file("cap/keep.txt"), "x");
  EXPECT_ERROR(CaptureWriter::create(dir.file("cap"), small_info(), std::nullopt), BadUsage, "cap",
               "not an empty folder");
  EXPECT_TRUE(std::filesystem::exists(dir.file("cap/keep.txt")));

  auto writer = CaptureWriter::create(dir.file("new"), small_info(), std::nullopt);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  InputFrame wrong = make_frame(0);
  wrong.color = testing::test_color(kW + 1, kH, 0);
  EXPECT_ERROR(writer->add_frame(wrong), BadUsage, "colour image is 9x6", "intrinsics say 8x6");
  ASSERT_TRUE(writer->add_frame(make_frame(1)).ok());
  EXPECT_ERROR(writer->add_frame(make_frame(0)), BadUsage, "does not increase");
  InputFrame no_pose = make_frame(2);
  no_pose.pose.reset();
  EXPECT_ERROR(writer->add_frame(no_pose), BadUsage, "every frame has a pose or none");
  // Without finish() only the .partial folder exists.
  EXPECT_FALSE(std::filesystem::exists(dir.file("new")));
}

// A static environment camera's image, the same for every frame, is stored once and listed per
// frame; a changed one is stored again, and a return to the first image is stored anew (only the
// last image written is compared).
TEST(CaptureWriter, AnUnchangedEnvironmentImageIsStoredOnce) {
  TempDir dir;
  auto writer = CaptureWriter::create(dir.file("cap"), small_info(), std::nullopt);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  std::vector<InputFrame> frames;
  for (int i = 0; i < 4; ++i) {
    frames.push_back(make_frame(i));
    frames.back().env = make_frame(i == 2 ? 1 : 0).env;  // env images A A B A
  }
  for (const InputFrame& f : frames) ASSERT_TRUE(writer->add_frame(f).ok());
  ASSERT_TRUE(writer->finish().ok());
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.file("cap/env"))) files += e.is_regular_file();
  EXPECT_EQ(files, 3u);  // frames 0, 2 and 3
  EXPECT_FALSE(std::filesystem::exists(dir.file("cap/env/000001.exr")));
  auto reader = CaptureReader::open(dir.file("cap"));
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->frame_count(), 4u);
  EXPECT_EQ(reader->entry(1).env, reader->entry(0).env);
  for (size_t i = 0; i < 4; ++i) {
    auto f = reader->read_frame(i);
    ASSERT_TRUE(f.ok()) << f.error().message;
    ASSERT_TRUE(f->env.has_value());
    EXPECT_EQ(f->env->data, frames[i].env->data) << "frame " << i;
  }
}

TEST(CaptureWriter, FrameWithoutPoseOrEnvWritesNoGroundtruth) {
  TempDir dir;
  CaptureInfo info = small_info();
  info.env_camera.reset();
  auto writer = CaptureWriter::create(dir.file("cap"), info, std::nullopt);
  ASSERT_TRUE(writer.ok());
  InputFrame f = make_frame(0);
  f.pose.reset();
  f.env.reset();
  ASSERT_TRUE(writer->add_frame(f).ok());
  ASSERT_TRUE(writer->finish().ok());
  EXPECT_FALSE(std::filesystem::exists(dir.file("cap/groundtruth.txt")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("cap/env.txt")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("cap/capture.json")));
  auto reader = CaptureReader::open(dir.file("cap"));
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_FALSE(reader->entry(0).pose.has_value());
  EXPECT_FALSE(reader->info().env_camera.has_value());
}

TEST(CaptureSource, ReplaysFramesInOrderThenEndOfStream) {
  testing::CaptureFixture f(3);
  auto source = make_capture_source(f.folder());
  ASSERT_TRUE(source.ok()) << source.error().message;
  EXPECT_TRUE(testing::contains((*source)->name(), f.folder()));
  EXPECT_EQ((*source)->info().color.width, kW);
  for (int i = 0; i < 3; ++i) {
    auto frame = (*source)->next(std::chrono::milliseconds(10));
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    EXPECT_EQ(frame->index, i);
    EXPECT_EQ(frame->color.data, testing::test_color(kW, kH, i).data);
  }
  EXPECT_ERROR((*source)->next(std::chrono::milliseconds(10)), EndOfStream, "3 frames");
  EXPECT_ERROR((*source)->next(std::chrono::milliseconds(10)), EndOfStream);
}

TEST(CaptureSource, OpenFailsWithReaderError) {
  TempDir dir;
  EXPECT_ERROR(make_capture_source(dir.file("none")), NotFound, "none");
}

}  // namespace
}  // namespace mrgi
