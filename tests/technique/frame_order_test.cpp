// When a frame's output comes back (Runtime::process, runtime.h): with N frames in flight the
// call given frame k returns frame k - N (the call waits for the slot frame k - N used), and
// flush() returns the last N in order. Measured, not assumed: the header states what this finds.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mrgi/runtime.h"
#include "synthetic_scene.h"
#include "capture/temp_dir.h"

namespace mrgi::test {
namespace {

TEST(FrameOrder, OutputsComeBackFramesInFlightCallsLaterAndFlushDrainsTheRest) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  for (int in_flight = 1; in_flight <= 3; ++in_flight) {
    RuntimeSettings s;
    s.technique = "baseline";
    s.level = 3;  // a fixed level: no scheduler warm-up runs
    s.frames_in_flight = in_flight;
    auto rt = create_runtime(s, scene.cameras(), scene.scene);
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    const int n = 6;
    for (int k = 0; k < n; ++k) {
      InputFrame f = scene.frame(k % 2);
      f.index = k;
      auto outs = (*rt)->process(f);
      ASSERT_TRUE(outs.ok()) << outs.error().message;
      std::vector<int64_t> got;
      for (const FrameOutput& o : *outs) got.push_back(o.stats.frame_index);
      const std::vector<int64_t> want = k >= in_flight ? std::vector<int64_t>{k - in_flight} : std::vector<int64_t>{};
      EXPECT_EQ(got, want) << in_flight << " in flight, the call given frame " << k;
    }
    auto rest = (*rt)->flush();
    ASSERT_TRUE(rest.ok()) << rest.error().message;
    std::vector<int64_t> got, want;
    for (const FrameOutput& o : *rest) got.push_back(o.stats.frame_index);
    for (int k = n - in_flight; k < n; ++k) want.push_back(k);
    EXPECT_EQ(got, want) << in_flight << " in flight: flush()";
  }
}

}  // namespace
}  // namespace mrgi::test
