// The Vulkan 1.2 path (DeviceSettings::vulkan_1_2: the instance asks for 1.2, synchronization2
// and dynamic rendering come from their KHR extensions) on lavapipe, which has 1.3: with
// validation on (a 1.3-only call would be a message, and a message fails process()), every pass
// kind runs (dir's rasterised maps and G-buffer, baseline's shadow maps, compute, transfers)
// and the frames equal the 1.3 path's bit for bit.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

std::vector<FrameOutput> run(const SyntheticScene& scene, const std::string& technique, bool vulkan_1_2) {
  RuntimeSettings s;
  s.device.validate = true;
  s.device.vulkan_1_2 = vulkan_1_2;
  s.technique = technique;
  s.level = 2;
  return run_synthetic_frames(scene, s, 2);
}

TEST(Vulkan12, EveryPassKindRunsOnTheExtensionPathAndGivesTheSameFrames) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  for (const char* technique : {"dir", "dlpv", "ssrt"}) {
    SCOPED_TRACE(technique);
    const std::vector<FrameOutput> core = run(scene, technique, false);
    const std::vector<FrameOutput> extensions = run(scene, technique, true);
    ASSERT_EQ(core.size(), 2u);
    ASSERT_EQ(extensions.size(), core.size());
    for (size_t i = 0; i < core.size(); ++i) {
      EXPECT_EQ(extensions[i].image.data, core[i].image.data) << "frame " << i;
      EXPECT_EQ(extensions[i].virtual_mask.data, core[i].virtual_mask.data) << "frame " << i;
    }
  }
}

}  // namespace
}  // namespace mrgi::test
