// Memory nothing wrote this frame is never read: every technique at its best and cheapest
// level (and dlpv at each level) gives the same frames, bit for bit, when every new allocation
// is filled with NaN bytes (DeviceSettings::poison_memory) as when it holds what the allocator
// gave (zero pages in a fresh process). Found this way: dlpv's volume lookup at the last used
// cell's centre gave the cell past it weight 0, and 0 x NaN is NaN (lpv_resolve.comp now writes
// that layer); the bench saw it as run-to-run noise (an earlier runtime's data in reused memory).
// golden_desk_160 (2 frames), validation layers on.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/replay_capture.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi::test {
namespace {

TEST(PoisonedMemory, EveryTechniqueGivesTheSameFrames) {
  auto capture = CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160");
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  for (const std::string& technique : technique_names()) {
    auto levels = technique_levels(technique);
    ASSERT_TRUE(levels.ok());
    std::vector<int> run_levels = {0, int(levels->size()) - 1};
    if (technique == "dlpv")
      for (int l = 1; l + 1 < int(levels->size()); ++l) run_levels.push_back(l);
    for (int level : run_levels) {
      std::vector<FrameOutput> outs[2];
      for (int poison = 0; poison < 2; ++poison) {
        RuntimeSettings s;
        s.device.validate = true;
        s.device.poison_memory = poison == 1;
        s.technique = technique;
        s.level = level;
        run_every_frame(*capture, s, outs[poison]);
        if (HasFatalFailure()) return;
        ASSERT_EQ(outs[poison].size(), capture->frame_count());
      }
      for (size_t i = 0; i < outs[0].size(); ++i) {
        EXPECT_TRUE(outs[0][i].image.data == outs[1][i].image.data)
            << technique << " level " << level << " frame " << i << ": output changed by poisoned memory";
        EXPECT_TRUE(outs[0][i].virtual_mask.data == outs[1][i].virtual_mask.data)
            << technique << " level " << level << " frame " << i;
      }
    }
  }
}

}  // namespace
}  // namespace mrgi::test
