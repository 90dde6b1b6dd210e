// Scene descriptions (strict validation) and `synth` (bit-identical, readable captures).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/shared_data.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_references.h"
#include "mrgi/reference/description.h"
#include "mrgi/reference/synth.h"

namespace fs = std::filesystem;

namespace mrgi::reference {
namespace {

const std::string kShared = mrgi::test::shared_root();

class SynthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Every description below names an environment map and a model from ../shared.
    MRGI_SKIP_WITHOUT_SHARED(kShared + "/data/models/bunny.glb");
    MRGI_SKIP_WITHOUT_SHARED(kShared + "/data/env/courtyard.exr");
    dir_ = fs::temp_directory_path() / ("mrgi_synth_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }

  // A tiny but complete description: real floor, box and spot lamp, a virtual bunny, an HDR
  // environment seen by a fisheye env camera.
  std::string tiny(const std::string& extra_root = "") {
    return R"({
  "version": 1, "frames": 2, "fps": 10,)" + extra_root + R"(
  "camera": {"width": 32, "height": 24, "fx": 30, "fy": 30, "exposure": 1.5},
  "camera_path": [{"time": 0, "position": [0, 0.6, -0.8], "look_at": [0, 0.05, 0]},
                  {"time": 0.1, "position": [0.1, 0.6, -0.8], "look_at": [0, 0.05, 0]}],
  "render": {"spp": 4, "max_depth": 3, "seed": 5},
  "real_objects": [
    {"shape": "plane", "size": [2, 2], "material": {"color": [0.7, 0.7, 0.7]}},
    {"shape": "box", "size": [0.1, 0.1, 0.1], "position": [0.2, 0.05, 0], "material": {"color": [0.2, 0.2, 0.8]}}],
  "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": 2,
              "inner_angle_deg": 30, "outer_angle_deg": 50}],
  "environment": {"image": ")" + kShared + R"(/data/env/courtyard.exr", "intensity": 0.3, "capture_width": 32},
  "virtual_objects": [{"gltf": ")" + kShared + R"(/data/models/bunny.glb", "position": [0, 0, 0], "scale": 1.0,
                       "velocity": [0.1, 0, 0]}],
  "env_camera": {"position": [0, 0.5, 0], "look_at": [0, 2, 0], "up": [0, 0, 1], "size": 16, "spp": 2}
})";
  }

  fs::path dir_;
};

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST_F(SynthTest, ReadsAValidDescription) {
  auto d = load_scene_description(write("ok.json", tiny()));
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_EQ(d->frames, 2);
  EXPECT_EQ(d->intrinsics.width, 32);
  EXPECT_DOUBLE_EQ(d->intrinsics.cx, 15.5);
  EXPECT_EQ(d->real_objects.size(), 2u);
  EXPECT_TRUE(d->env_camera.has_value());
  const Pose mid = camera_pose_at(*d, 0.05);
  EXPECT_NEAR(mid.translation.x, 0.05, 1e-9);
  // The camera looks along +z in its own frame: that axis points at the look-at point.
  const glm::dvec3 forward = glm::dmat3(mid.matrix()) * glm::dvec3(0, 0, 1);
  EXPECT_GT(glm::dot(forward, glm::normalize(glm::dvec3(0, 0.05, 0) - mid.translation)), 0.99);
}

TEST_F(SynthTest, RefusesBrokenDescriptions) {
  struct Case {
    std::string text, must_mention;
  };
  const std::string base = tiny();
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    const size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  const Case cases[] = {
      {with("\"frames\": 2", "\"frames\": 2, \"colour\": 1"), "colour"},                 // unknown key
      {with("\"spp\": 4", "\"spp\": \"many\""), "render.spp"},                           // bad type
      {with("\"spp\": 4", "\"spp\": 4, \"sample\": 1"), "sample"},                       // unknown nested key
      {with("models/bunny.glb", "models/missing.glb"), "virtual_objects[0].gltf"},       // missing glTF
      {with("\"intensity\": 2,", "\"intensity\": NaN,"), "ok.json"},                     // NaN is not JSON
      {with("\"intensity\": 2,", "\"intensity\": -2,"), "lights[0].intensity"},          // negative
      {with("\"outer_angle_deg\": 50", "\"outer_angle_deg\": 20"), "inner_angle_deg"},   // inner > outer
      {with("\"size\": [2, 2]", "\"size\": [2, 2, 2]"), "real_objects[0].size"},         // plane is 2-D
      {with("\"look_at\": [0, 0.05, 0]}", "\"look_at\": [0, 0.6, -0.8]}"), "look_at"},   // degenerate
      {with("\"version\": 1", "\"version\": 2"), "version"},
  };
  for (const Case& c : cases) {
    auto d = load_scene_description(write("ok.json", c.text));
    ASSERT_FALSE(d.ok()) << "accepted; expected a complaint about " << c.must_mention;
    EXPECT_EQ(d.error().kind, ErrorKind::BadInput);
    EXPECT_NE(d.error().message.find(c.must_mention), std::string::npos) << d.error().message;
    EXPECT_NE(d.error().message.find("ok.json"), std::string::npos) << d.error().message;
  }
}

TEST_F(SynthTest, TwoSynthsAreBitIdenticalAndReadable) {
  auto d = load_scene_description(write("tiny.json", tiny()));
  ASSERT_TRUE(d.ok()) << d.error().message;
  SynthOptions o;
  o.threads = 2;
  o.out = (dir_ / "a").string();
  auto ra = synthesize_capture(*d, o);
  ASSERT_TRUE(ra.ok()) << ra.error().message;
  o.threads = 1;
  o.out = (dir_ / "b").string();
  ASSERT_TRUE(synthesize_capture(*d, o).ok());
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "a")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir_ / "a");
    EXPECT_EQ(read_all(e.path()), read_all(dir_ / "b" / rel)) << rel;
    ++files;
  }
  EXPECT_GE(files, 2u * 5u);  // rgb, depth, env, reference, mask per frame
  // Writing over an existing capture is refused.
  EXPECT_FALSE(synthesize_capture(*d, o).ok());

  auto capture = CaptureReader::open((dir_ / "a").string());
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  EXPECT_EQ(capture->frame_count(), 2u);
  EXPECT_TRUE(capture->has_references());
  ASSERT_TRUE(capture->info().env_camera.has_value());
  EXPECT_EQ(capture->info().env_camera->model, EnvModel::FisheyeEquidistant);
  ASSERT_TRUE(capture->scene().has_value());
  ASSERT_EQ(capture->scene()->virtual_objects.size(), 1u);
  EXPECT_TRUE(fs::exists(capture->scene()->virtual_objects[0].gltf));
  EXPECT_TRUE(capture->scene()->environment.from_env_camera);
  ASSERT_EQ(capture->scene()->lights.size(), 1u);
  EXPECT_TRUE(capture->scene()->lights[0].real);
  auto frame = capture->read_frame(1);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  ASSERT_TRUE(frame->pose.has_value());
  EXPECT_NEAR(frame->pose->translation.x, 0.1, 1e-6);
  ASSERT_TRUE(frame->env.has_value());
  auto mask = capture->read_reference_mask(0);
  ASSERT_TRUE(mask.ok());
  auto reference = capture->read_reference(0);
  ASSERT_TRUE(reference.ok());
  auto f0 = capture->read_frame(0);
  ASSERT_TRUE(f0.ok());
  // The bunny is seen (mask), the reference differs from the camera frame there, and outside the
  // mask most pixels are equal (the bunny only shadows and tints a part of the floor).
  size_t virtual_pixels = 0, differing_inside = 0, equal_outside = 0, outside = 0, depth_pixels = 0;
  for (size_t i = 0; i < mask->pixel_count(); ++i) {
    const bool v = mask->data[i] != 0;
    const bool same = std::equal(&f0->color.data[3 * i], &f0->color.data[3 * i + 3], &reference->data[3 * i]);
    virtual_pixels += v;
    differing_inside += v && !same;
    outside += !v;
    equal_outside += !v && same;
    depth_pixels += f0->depth.data[i] != 0;
  }
  EXPECT_GT(virtual_pixels, 5u);
  EXPECT_GT(differing_inside, virtual_pixels / 2);
  EXPECT_GT(equal_outside, outside / 4);
  EXPECT_GT(depth_pixels, mask->pixel_count() / 4);  // the upper part sees past the floor
}

// References are stored as deltas by default; a plain render converted afterwards (how the suite's
// older captures were converted) must give the very same files.
TEST_F(SynthTest, DeltaReferencesEqualConvertedPlainOnes) {
  auto d = load_scene_description(write("tiny.json", tiny()));
  ASSERT_TRUE(d.ok()) << d.error().message;
  SynthOptions o;
  o.threads = 2;
  o.frames = 2;
  o.spp = 2;
  o.out = (dir_ / "delta").string();
  ASSERT_TRUE(synthesize_capture(*d, o).ok());
  o.out = (dir_ / "plain").string();
  o.references = ReferenceStorage::Plain;
  ASSERT_TRUE(synthesize_capture(*d, o).ok());
  EXPECT_TRUE(fs::exists(dir_ / "delta" / "reference" / "000001.delta.png"));
  EXPECT_TRUE(fs::exists(dir_ / "plain" / "reference" / "000001.png"));
  auto plain = CaptureReader::open((dir_ / "plain").string());
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  auto plain_ref = plain->read_reference(1);
  ASSERT_TRUE(plain_ref.ok());

  auto converted = convert_capture_references((dir_ / "plain").string(), ReferenceStorage::Delta);
  ASSERT_TRUE(converted.ok()) << converted.error().message;
  EXPECT_EQ(converted->converted, 2u);
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "delta")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir_ / "delta");
    EXPECT_EQ(read_all(e.path()), read_all(dir_ / "plain" / rel)) << rel;
    ++files;
  }
  EXPECT_GE(files, 2u * 5u);
  auto delta = CaptureReader::open((dir_ / "delta").string());
  ASSERT_TRUE(delta.ok()) << delta.error().message;
  auto delta_ref = delta->read_reference(1);
  ASSERT_TRUE(delta_ref.ok()) << delta_ref.error().message;
  EXPECT_EQ(delta_ref->data, plain_ref->data);
}

// A render split over runs (stop_after, then resume) gives the same files and report as one run.
TEST_F(SynthTest, ResumedRenderIsBitIdenticalToAnUninterruptedOne) {
  auto d = load_scene_description(write("tiny.json", tiny()));
  ASSERT_TRUE(d.ok()) << d.error().message;
  SynthOptions o;
  o.threads = 2;
  o.frames = 3;
  o.noise_floor_seed = 77;
  o.out = (dir_ / "whole").string();
  auto whole = synthesize_capture(*d, o);
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  ASSERT_TRUE(whole->noise_floor.has_value());

  o.out = (dir_ / "split").string();
  o.stop_after = 1;
  o.resume = true;  // no split.partial yet: starts from frame 0
  auto first = synthesize_capture(*d, o);
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_FALSE(first->finished);
  EXPECT_EQ(first->frames_rendered, 1);
  EXPECT_FALSE(fs::exists(dir_ / "split"));
  EXPECT_TRUE(fs::exists(dir_ / "split.partial" / "synth_resume.json"));

  // Another spp (or description, or input file) is refused, naming what the partial was made with.
  SynthOptions other = o;
  other.spp = 3;
  auto refused = synthesize_capture(*d, other);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(refused.error().message.find("spp 4"), std::string::npos) << refused.error().message;
  EXPECT_NE(refused.error().message.find("spp 3"), std::string::npos) << refused.error().message;

  // A kill in the middle of frame 1 left half its files behind.
  std::ofstream(dir_ / "split.partial" / "rgb" / "000001.png") << "half";
  auto second = synthesize_capture(*d, o);
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_EQ(second->frames_resumed, 1);
  EXPECT_EQ(second->frames_rendered, 1);
  EXPECT_FALSE(second->finished);
  o.stop_after.reset();
  auto last = synthesize_capture(*d, o);
  ASSERT_TRUE(last.ok()) << last.error().message;
  EXPECT_TRUE(last->finished);
  EXPECT_EQ(last->frames_resumed, 2);
  EXPECT_EQ(last->frames_rendered, 1);
  ASSERT_TRUE(last->noise_floor.has_value());  // frame 0's, kept across the runs
  EXPECT_EQ(last->noise_floor->rde_all, whole->noise_floor->rde_all);
  EXPECT_EQ(last->noise_floor->delta_rms, whole->noise_floor->delta_rms);
  EXPECT_EQ(last->dropped_samples, whole->dropped_samples);
  // Render time adds up over the runs: more than this last run's one frame took.
  EXPECT_GT(last->frame_seconds, 0.0);
  EXPECT_GT(last->frame_seconds, second->frame_seconds - 1e-9);
  EXPECT_GE(second->frame_seconds, first->frame_seconds);

  size_t files = 0, split_files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "whole")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir_ / "whole");
    EXPECT_EQ(read_all(e.path()), read_all(dir_ / "split" / rel)) << rel;
    ++files;
  }
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "split")) split_files += e.is_regular_file();
  EXPECT_EQ(split_files, files);  // no resume bookkeeping left in the capture
  EXPECT_GE(files, 3u * 5u);
  EXPECT_FALSE(fs::exists(dir_ / "split.partial"));
  // A finished capture is not resumed (nor written over).
  EXPECT_FALSE(synthesize_capture(*d, o).ok());
}

TEST_F(SynthTest, ImageEnvironmentIsCopiedIntoTheCapture) {
  std::string text = tiny();
  const size_t at = text.find(",\n  \"env_camera\"");
  text = text.substr(0, at) + "\n}";
  auto d = load_scene_description(write("noenvcam.json", text));
  ASSERT_TRUE(d.ok()) << d.error().message;
  SynthOptions o;
  o.out = (dir_ / "c").string();
  o.frames = 1;
  o.spp = 1;
  ASSERT_TRUE(synthesize_capture(*d, o).ok());
  auto capture = CaptureReader::open(o.out);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  ASSERT_TRUE(capture->scene()->environment.present);
  EXPECT_FALSE(capture->scene()->environment.from_env_camera);
  auto env = load_hdr_image(capture->scene()->environment.image);
  ASSERT_TRUE(env.ok()) << env.error().message;
  EXPECT_EQ(env->width, 32);
  EXPECT_EQ(env->height, 16);
}

// `--from-renders`: the frames come from another renderer's EXRs (tools/cycles), through the same
// sensor models and writer; bad inputs are refused naming the file before anything is written.
TEST_F(SynthTest, FromRendersTakesTheImagesAndRefusesBadOnes) {
  auto d = load_scene_description(write("ok.json", tiny()));
  ASSERT_TRUE(d.ok()) << d.error().message;
  const fs::path renders = dir_ / "renders";
  fs::create_directories(renders);
  auto file = [&](int f, const char* what) {
    char name[64];
    std::snprintf(name, sizeof name, "%06d_%s.exr", f, what);
    return (renders / name).string();
  };
  auto filled = [](int w, int h, float v) { return ImageRGBF(w, h, v); };
  for (int f = 0; f < 2; ++f) {
    ImageRGBF c = filled(32, 24, 0.2f), g = c, mask = filled(32, 24, 0.0f);
    for (int y = 8; y < 16; ++y)
      for (int x = 10; x < 20; ++x) {
        for (int k = 0; k < 3; ++k) g.at(x, y)[k] = 0.5f;
        mask.at(x, y)[0] = 1.0f;
      }
    ImageRGBF normal(32, 24);
    for (size_t i = 0; i < normal.pixel_count(); ++i) {  // 0.5 + 0.5 n, n = +y (the floor)
      normal.data[3 * i] = 0.5f;
      normal.data[3 * i + 1] = 1.0f;
      normal.data[3 * i + 2] = 0.5f;
    }
    ASSERT_TRUE(write_exr(file(f, "C"), c).ok());
    ASSERT_TRUE(write_exr(file(f, "G"), g).ok());
    ASSERT_TRUE(write_exr(file(f, "depth"), filled(32, 24, 1.0f)).ok());
    ASSERT_TRUE(write_exr(file(f, "normal"), normal).ok());
    ASSERT_TRUE(write_exr(file(f, "mask"), mask).ok());
    if (f == 0) {
      ASSERT_TRUE(write_exr(file(f, "env"), filled(16, 16, 0.1f)).ok());
    }
  }
  SynthOptions o;
  o.out = (dir_ / "cap").string();
  o.from_renders = renders.string();
  // Frame 1 has no env image: refused before anything is written.
  auto missing = synthesize_capture(*d, o);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("000001_env.exr: missing"), std::string::npos) << missing.error().message;
  EXPECT_FALSE(fs::exists(dir_ / "cap.partial"));
  // The wrong size is refused naming the file and the size it must have.
  ASSERT_TRUE(write_exr(file(1, "env"), filled(8, 8, 0.1f)).ok());
  auto wrong = synthesize_capture(*d, o);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("000001_env.exr: is 8x8, must be 16x16"), std::string::npos)
      << wrong.error().message;
  // Options that only a path-traced render has are refused.
  SynthOptions with_spp = o;
  with_spp.spp = 4;
  EXPECT_FALSE(synthesize_capture(*d, with_spp).ok());

  ASSERT_TRUE(write_exr(file(1, "env"), filled(16, 16, 0.1f)).ok());
  auto report = synthesize_capture(*d, o);
  ASSERT_TRUE(report.ok()) << report.error().message;
  auto capture = CaptureReader::open(o.out);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  ASSERT_EQ(capture->frame_count(), 2u);
  auto f0 = capture->read_frame(0);
  auto reference = capture->read_reference(0);
  auto mask = capture->read_reference_mask(0);
  ASSERT_TRUE(f0.ok() && reference.ok() && mask.ok());
  ASSERT_TRUE(f0->env.has_value());
  // The camera model (exposure 1.5, sRGB) applied to the given radiance; G differs from C exactly
  // inside the given mask; depth 1 m is measured (Kinect model: within a few mm).
  const uint8_t c8 = f0->color.data[0];
  EXPECT_NEAR(c8, 255.0 * std::pow(0.2 * 1.5, 1.0 / 2.4) * 1.055 - 0.055 * 255.0, 1.5);
  size_t virtual_pixels = 0, differing = 0, measured = 0;
  for (size_t i = 0; i < mask->pixel_count(); ++i) {
    virtual_pixels += mask->data[i] != 0;
    differing += reference->data[3 * i] != f0->color.data[3 * i];
    if (f0->depth.data[i]) {
      ++measured;
      EXPECT_NEAR(f0->depth.data[i] / capture->info().depth_scale, 1.0, 0.02);
    }
  }
  EXPECT_EQ(virtual_pixels, 80u);
  EXPECT_EQ(differing, 80u);
  EXPECT_GT(measured, mask->pixel_count() / 2);
}

}  // namespace
}  // namespace mrgi::reference
