// The per-frame skip of runtime/influence.h: frames where no virtual object or its shadow can be
// seen run no virtual G-buffer and no technique, and their output must equal what the full
// pipeline gives (the camera frame) within one 8-bit step. Validation layers on.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <set>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "runtime/influence.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

runtime::InfluenceQuery camera_at_origin(glm::dvec3 lo, glm::dvec3 hi) {
  runtime::InfluenceQuery q;
  q.box_min = lo;
  q.box_max = hi;
  q.margin_m = 0.0;
  q.camera_to_world = glm::dmat4(1.0);  // looking along +z, x right, y down
  q.camera = Intrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};
  return q;
}

LightDesc point_lamp(glm::vec3 p, bool real = true) {
  LightDesc l;
  l.type = LightType::Point;
  l.position = p;
  l.real = real;
  return l;
}

TEST(Influence, ObjectInViewIsInView) {
  EXPECT_TRUE(runtime::virtual_influence_in_view(camera_at_origin({-0.1, -0.1, 2.0}, {0.1, 0.1, 2.2}), {}));
}

TEST(Influence, ObjectBesideTheViewWhoseShadowFallsIntoItIsInView) {
  // Box 5 m to the right; a lamp further right throws its shadow to the left, into the view.
  const auto q = camera_at_origin({5.0, -0.1, 5.0}, {5.2, 0.1, 5.2});
  EXPECT_TRUE(runtime::virtual_influence_in_view(q, {point_lamp({10.0f, 0.0f, 5.1f})}));
  // The same box with the lamp on the view's side throws its shadow away from the view.
  EXPECT_FALSE(runtime::virtual_influence_in_view(q, {point_lamp({0.0f, 0.0f, 5.1f})}));
  EXPECT_FALSE(runtime::virtual_influence_in_view(q, {}));
}

TEST(Influence, ObjectBehindTheCameraLitFromBehindIsInView) {
  const auto q = camera_at_origin({-0.1, -0.1, -2.2}, {0.1, 0.1, -2.0});
  EXPECT_FALSE(runtime::virtual_influence_in_view(q, {}));
  EXPECT_TRUE(runtime::virtual_influence_in_view(q, {point_lamp({0.0f, 0.0f, -5.0f})}));
  LightDesc sun;
  sun.type = LightType::Directional;
  sun.direction = {0.0f, 0.0f, -1.0f};  // light travels away from the view
  EXPECT_FALSE(runtime::virtual_influence_in_view(q, {sun}));
}

TEST(Influence, AVirtualLampAffectsEveryFrame) {
  const auto q = camera_at_origin({-0.1, -0.1, -2.2}, {0.1, 0.1, -2.0});
  EXPECT_TRUE(runtime::virtual_influence_in_view(q, {point_lamp({0.0f, 0.0f, 5.0f}, false)}));
}

FrameOutput run_one(const SyntheticScene& s, const SceneDesc& scene, bool skips, bool profiled = false,
                    int output_width = 0, int output_height = 0) {
  RuntimeSettings rs;
  rs.device.validate = true;
  rs.profile_passes = profiled;
  rs.output_width = output_width;
  rs.output_height = output_height;
  rs.technique = "baseline";
  rs.level = 0;
  rs.skip_unaffected_frames = skips;
  auto rt = create_runtime(rs, s.cameras(), scene);
  EXPECT_TRUE(rt.ok()) << rt.error().message;
  if (!rt.ok()) return {};
  auto a = (*rt)->process(s.frame(0));
  EXPECT_TRUE(a.ok()) << a.error().message;
  auto b = (*rt)->flush();
  EXPECT_TRUE(b.ok()) << b.error().message;
  std::vector<FrameOutput> outs;
  if (a.ok())
    for (auto& o : *a) outs.push_back(std::move(o));
  if (b.ok())
    for (auto& o : *b) outs.push_back(std::move(o));
  EXPECT_EQ(outs.size(), 1u);
  return outs.empty() ? FrameOutput{} : std::move(outs[0]);
}

bool reports_skip(const FrameOutput& o) {
  for (const std::string& s : o.stats.skipped)
    if (s.find("no virtual object or its shadow in view") != std::string::npos) return true;
  return false;
}

TEST(FrameSkip, OutOfViewObjectSkipsTheTechniqueWithoutChangingTheOutput) {
  const mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  SceneDesc far = s.scene;
  for (auto& v : far.virtual_objects) v.placement.position += glm::vec3(30.0f, 0.0f, 0.0f);
  const FrameOutput skipped = run_one(s, far, true);
  const FrameOutput full = run_one(s, far, false);
  ASSERT_FALSE(skipped.image.empty());
  ASSERT_FALSE(full.image.empty());
  EXPECT_TRUE(reports_skip(skipped));
  EXPECT_FALSE(reports_skip(full));
  int worst = 0;
  for (size_t i = 0; i < full.image.data.size(); ++i)
    worst = std::max(worst, std::abs(int(full.image.data[i]) - int(skipped.image.data[i])));
  EXPECT_LE(worst, 1) << "skipping must not change the output beyond one 8-bit step";
  bool ran_shadow = false;
  for (const PassTiming& p : skipped.stats.passes) ran_shadow = ran_shadow || p.name.rfind("shadow", 0) == 0;
  EXPECT_FALSE(ran_shadow);
}

// The lean skeleton: a frame nothing virtual affects runs no GPU pass at the camera's size, and
// its output is the camera frame byte for byte; at another output size compose's camera-copy
// pipeline resamples it, and nothing else runs.
TEST(FrameSkip, UnaffectedFrameIsTheCameraFrameWithoutAPass) {
  const mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  SceneDesc far = s.scene;
  for (auto& v : far.virtual_objects) v.placement.position += glm::vec3(30.0f, 0.0f, 0.0f);
  const FrameOutput o = run_one(s, far, true);
  ASSERT_FALSE(o.image.empty());
  EXPECT_TRUE(o.stats.passes.empty());
  bool recon_skip = false, compose_skip = false;
  for (const std::string& sk : o.stats.skipped) {
    recon_skip = recon_skip || sk.rfind("recon:", 0) == 0;
    compose_skip = compose_skip || sk.rfind("compose:", 0) == 0;
  }
  EXPECT_TRUE(recon_skip);
  EXPECT_TRUE(compose_skip);
  const InputFrame in = s.frame(0);
  ASSERT_EQ(size_t(o.image.width) * o.image.height, size_t(in.color.width) * in.color.height);
  int different = 0;
  for (size_t i = 0; i < size_t(in.color.width) * in.color.height; ++i) {
    for (int c = 0; c < 3; ++c) different += o.image.data[i * 4 + c] != in.color.data[i * 3 + c];
    different += o.image.data[i * 4 + 3] != 255;
  }
  EXPECT_EQ(different, 0);
  for (uint8_t m : o.virtual_mask.data) EXPECT_EQ(m, 0);

  const int w = in.color.width / 2, h = in.color.height / 2;
  const FrameOutput half = run_one(s, far, true, false, w, h);
  ASSERT_EQ(half.image.width, w);
  std::vector<std::string> names;
  for (const PassTiming& p : half.stats.passes) names.push_back(p.name);
  EXPECT_EQ(names, std::vector<std::string>{"compose"});
  const ImageRGB8 expect = resize_bilinear(in.color, w, h);
  int worst = 0;
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(half.image.data[i * 4 + c]) - int(expect.data[i * 3 + c])));
  // compose resamples on linear values, resize_bilinear on encoded ones: close, not equal.
  EXPECT_LE(worst, 24);
}

// Profiling mode: every pass its own host-timed submission, and they add up to the frame.
TEST(FrameSkip, ProfiledFramePassesAddUpAndMatchTheNormalOutput) {
  const mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  const FrameOutput normal = run_one(s, s.scene, true, false);
  const FrameOutput profiled = run_one(s, s.scene, true, true);
  ASSERT_FALSE(profiled.image.empty());
  EXPECT_FALSE(normal.stats.profiled);
  EXPECT_TRUE(profiled.stats.profiled);
  ASSERT_GT(profiled.stats.passes.size(), 2u);
  double sum = 0.0;
  for (const PassTiming& p : profiled.stats.passes) {
    EXPECT_GE(p.gpu_ms, 0.0) << p.name;  // the submission overhead is subtracted
    sum += p.gpu_ms;
  }
  EXPECT_NEAR(profiled.stats.gpu_total_ms, sum, 1e-9);
  EXPECT_GE(profiled.stats.host_ms, 0.0);
  EXPECT_EQ(normal.image.data, profiled.image.data);
}

TEST(FrameSkip, ObjectInViewIsNotSkipped) {
  const mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  const FrameOutput o = run_one(s, s.scene, true);
  ASSERT_FALSE(o.image.empty());
  EXPECT_FALSE(reports_skip(o));
  int virtual_pixels = 0;
  for (uint8_t m : o.virtual_mask.data) virtual_pixels += m != 0;
  EXPECT_GT(virtual_pixels, 0);
}

}  // namespace
}  // namespace mrgi::test

namespace mrgi::test {
namespace {

// Runtime::recycle: a frame handed back is filled again (its storage reused: no fresh memory per
// frame) and every output equals a runtime's that never recycles, for composed frames and for
// camera copies (object out of view). Frames of another size are not reused.
TEST(Runtime, RecycledOutputsAreRefilledAndUnchanged) {
  const mrgi::testing::TempDir dir;
  const SyntheticScene s = SyntheticScene::create(dir.str());
  for (const bool in_view : {true, false}) {
    SceneDesc scene = s.scene;
    if (!in_view)
      for (auto& v : scene.virtual_objects) v.placement.position += glm::vec3(30.0f, 0.0f, 0.0f);
    RuntimeSettings rs;
    rs.device.validate = true;
    rs.technique = "baseline";
    rs.level = 3;
    auto recycling = create_runtime(rs, s.cameras(), scene);
    auto plain = create_runtime(rs, s.cameras(), scene);
    ASSERT_TRUE(recycling.ok() && plain.ok());
    std::vector<FrameOutput> got, want;
    std::set<const uint8_t*> storage;
    size_t reused = 0;
    for (int64_t k = 0; k < 6; ++k) {
      auto a = (*recycling)->process(s.frame(k));
      auto b = (*plain)->process(s.frame(k));
      ASSERT_TRUE(a.ok() && b.ok());
      for (FrameOutput& o : *a) {
        reused += storage.count(o.image.data.data());
        storage.insert(o.image.data.data());
        got.push_back(o);                     // a copy for the comparison below
        (*recycling)->recycle(std::move(o));  // the storage goes back
      }
      for (FrameOutput& o : *b) want.push_back(std::move(o));
    }
    auto a = (*recycling)->flush();
    auto b = (*plain)->flush();
    ASSERT_TRUE(a.ok() && b.ok());
    for (FrameOutput& o : *a) got.push_back(std::move(o));
    for (FrameOutput& o : *b) want.push_back(std::move(o));
    ASSERT_EQ(got.size(), want.size());
    EXPECT_GE(reused, 3u) << "recycled images were not filled again";
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].stats.frame_index, want[i].stats.frame_index);
      EXPECT_TRUE(got[i].image.data == want[i].image.data) << "frame " << i << ", in view " << in_view;
      EXPECT_TRUE(got[i].virtual_mask.data == want[i].virtual_mask.data) << "frame " << i;
    }
    FrameOutput other;
    other.image = ImageRGBA8(8, 8);
    (*recycling)->recycle(std::move(other));  // another size: dropped, not reused
    auto c = (*recycling)->process(s.frame(7));
    auto d = (*recycling)->flush();
    ASSERT_TRUE(c.ok() && d.ok());
    for (const FrameOutput& o : *d) EXPECT_EQ(o.image.width, got[0].image.width);
  }
}

}  // namespace
}  // namespace mrgi::test
