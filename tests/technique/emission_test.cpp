// glTF emissive materials: a virtual surface's emission is added to its
// radiance by every technique, so its pixels brighten by exactly the emitted radiance (times the
// exposure) and the real pixels stay as they were. Validation layers on.
#include <gtest/gtest.h>

#include <string>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

FrameOutput first_frame(const std::string& technique, const glm::vec3& emission) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str(), emission);
  RuntimeSettings s;
  s.device.validate = true;
  s.technique = technique;
  s.level = 0;
  auto rt = create_runtime(s, scene.cameras(), scene.scene);
  EXPECT_TRUE(rt.ok()) << (rt.ok() ? "" : rt.error().message);
  if (!rt.ok()) return {};
  std::vector<FrameOutput> outs;
  auto out = (*rt)->process(scene.frame(0));
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  if (out.ok())
    for (auto& o : *out) outs.push_back(std::move(o));
  auto rest = (*rt)->flush();
  EXPECT_TRUE(rest.ok()) << (rest.ok() ? "" : rest.error().message);
  if (rest.ok())
    for (auto& o : *rest) outs.push_back(std::move(o));
  EXPECT_FALSE(outs.empty());
  return outs.empty() ? FrameOutput{} : std::move(outs.back());
}

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

class Emission : public ::testing::TestWithParam<std::string> {};

TEST_P(Emission, VirtualPixelsBrightenByTheEmittedRadianceAndRealOnesStay) {
  const glm::vec3 emission(0.30f, 0.12f, 0.0f);
  const FrameOutput plain = first_frame(GetParam(), glm::vec3(0.0f));
  const FrameOutput glowing = first_frame(GetParam(), emission);
  ASSERT_EQ(plain.image.data.size(), glowing.image.data.size());
  ASSERT_GT(plain.image.data.size(), 0u);
  EXPECT_EQ(plain.virtual_mask.data, glowing.virtual_mask.data);
  int tested = 0;
  for (int v = 0; v < plain.image.height; ++v) {
    for (int u = 0; u < plain.image.width; ++u) {
      const uint8_t* a = plain.image.at(u, v);
      const uint8_t* b = glowing.image.at(u, v);
      if (plain.virtual_mask.at(u, v)[0] == 0) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(a[c], b[c]) << "real pixel " << u << "," << v;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const float want = lin(a[c]) + emission[c];  // exposure 1 (synthetic_scene.h)
        if (want > 0.95f) continue;                    // the camera model clips at 1
        EXPECT_NEAR(lin(b[c]), want, 0.01f) << u << "," << v << " channel " << c;
        ++tested;
      }
    }
  }
  EXPECT_GT(tested, 60);
}

INSTANTIATE_TEST_SUITE_P(Techniques, Emission, ::testing::Values("baseline", "ssrt"),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

}  // namespace
}  // namespace mrgi::test
