// Every technique runs on a capture whose scene.json declares no lamp and no environment,
// lights its virtual object with the light stage's estimate (not black), and says in every
// frame's notes where the light came from. Validation layers on.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi {
namespace {

TEST(UndeclaredLight, EveryTechniqueLightsTheObjectFromTheEstimateAndSaysSo) {
  auto capture = CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160");
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  SceneDesc scene = *capture->scene();
  scene.lights.clear();
  scene.environment = EnvironmentDesc{};
  ASSERT_FALSE(scene.virtual_objects.empty());
  for (const std::string& technique : technique_names()) {
    auto levels = technique_levels(technique);
    ASSERT_TRUE(levels.ok());
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = technique;
    s.level = int(levels->size()) - 1;  // the cheapest: the light stage is the same at every level
    auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                             scene);
    ASSERT_TRUE(rt.ok()) << technique << ": " << rt.error().message;
    std::vector<FrameOutput> outs;
    for (size_t i = 0; i < capture->frame_count(); ++i) {
      auto f = capture->read_frame(i);
      ASSERT_TRUE(f.ok());
      f->index = int64_t(i);
      auto o = (*rt)->process(*f);
      ASSERT_TRUE(o.ok()) << technique << ": " << o.error().message;
      for (auto& x : *o) outs.push_back(std::move(x));
    }
    auto rest = (*rt)->flush();
    ASSERT_TRUE(rest.ok()) << technique << ": " << rest.error().message;
    for (auto& x : *rest) outs.push_back(std::move(x));
    ASSERT_EQ(outs.size(), capture->frame_count()) << technique;
    for (const FrameOutput& out : outs) {
      bool named = false;
      for (const std::string& n : out.stats.notes) named = named || n.find("light: probeless estimate") == 0;
      EXPECT_TRUE(named) << technique << " frame " << out.stats.frame_index << ": no note names the light's source";
      ASSERT_TRUE(out.light.has_value()) << technique;
      EXPECT_TRUE(out.light->valid) << technique;
      // The virtual object is lit: its pixels are far from black on average.
      double sum = 0.0;
      size_t count = 0;
      for (size_t p = 0; p < out.virtual_mask.data.size(); ++p) {
        if (out.virtual_mask.data[p] == 0) continue;
        const uint8_t* c = &out.image.data[p * 4];
        sum += (int(c[0]) + int(c[1]) + int(c[2])) / 3.0;
        ++count;
      }
      ASSERT_GT(count, 20u) << technique << ": the virtual object is not in view";
      EXPECT_GT(sum / double(count), 25.0) << technique << " frame " << out.stats.frame_index
                                           << ": the virtual object is (nearly) black";
    }
  }
}

}  // namespace
}  // namespace mrgi
