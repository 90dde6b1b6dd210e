// dir's ablations (mrgi/research.h DirAblation) on the bundled 160x120 desk capture (a real spot
// lamp, a virtual bunny on a real desk in front of a wall), validation on: each changes the
// frames (it is not ignored) and keeps them finite. The synthetic scene of tests/technique has
// no real surface the changed VPL light reaches (a flat floor seen from above), hence this one.
// (no_environment_vpls: this capture has no environment; tests/technique/dir_test.cpp measures
// it on the synthetic scene's sky.)
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "common/replay_capture.h"
#include "mrgi/research.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi {
namespace {

TEST(DirAblation, EachChangesTheFrames) {
  auto capture = CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160");
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  auto run = [&](const DirAblation& a, std::vector<FrameOutput>& outs) {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = "dir";
    s.level = 1;
    auto research = std::make_shared<ResearchSettings>();
    research->dir = a;
    s.research = research;
    test::run_every_frame(*capture, s, outs);
  };
  std::vector<FrameOutput> paper;
  run(DirAblation{}, paper);
  if (HasFatalFailure()) return;
  ASSERT_FALSE(paper.empty());
  DirAblation one, no_ir, one_bounce;
  one.one_shadow_map = true;
  no_ir.no_real_only_vpls = true;
  one_bounce.one_bounce = true;  // level 1 (high) has bounce slots
  for (const DirAblation& a : {one, no_ir, one_bounce}) {
    SCOPED_TRACE(a.one_shadow_map ? "one_shadow_map" : a.no_real_only_vpls ? "no_real_only_vpls" : "one_bounce");
    std::vector<FrameOutput> outs;
    run(a, outs);
    if (HasFatalFailure()) return;
    ASSERT_EQ(outs.size(), paper.size());
    size_t changed = 0;
    for (size_t i = 0; i < outs.size(); ++i)
      for (size_t k = 0; k < outs[i].image.data.size(); ++k) changed += outs[i].image.data[k] != paper[i].image.data[k];
    EXPECT_GT(changed, 0u) << "the ablation must change the frames";
  }
}

}  // namespace
}  // namespace mrgi
