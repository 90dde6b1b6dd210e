// ssrt against the path-traced reference on the suite's environment-lit scene (perf/suite/
// env_fisheye: 640x480, 8 frames, 512 spp, courtyard HDR with a sun 34 degrees up behind the
// camera), validation layers on: issue 4's "done when" as a test. The probeless estimate's
// dominant direction is compared with the band-1 direction of each frame's environment image,
// and the pooled RDE with `baseline`'s, which reads that environment image directly.
//
// Bounds: measured (session 4, lavapipe) plus a margin. fast: direction 8.5 median / 9.0 worst
// degrees, RDE 0.583; fastest: 7.4 / 7.8 degrees, RDE 0.618; baseline high: RDE 0.629.
// The full and half levels take about 4 s and 1 s a frame on lavapipe, too slow for CI's
// budget for one test; their figures are in ssrt.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "common/replay_capture.h"

namespace mrgi {
namespace {

const std::string kCapture = std::string(MRGI_SOURCE_DIR) + "/perf/suite/env_fisheye";

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

TEST(GoldenSsrt, EnvFisheyeLightDirectionAndRdeBeatBaseline) {
  const test::ReplayResult base = test::replay_capture(kCapture, "baseline", 0);
  ASSERT_TRUE(base.any && base.pooled.all.rde_defined);
  std::printf("baseline high: RDE all %.3f real %.3f virtual %.3f\n", base.pooled.all.rde,
              base.pooled.real.rde, base.pooled.virtual_.rde);
  struct Case {
    const char* level;
    int index;
    double median_deg, worst_deg;
  };
  for (const Case c : {Case{"fast", 2, 15.0, 15.0}, Case{"fastest", 3, 15.0, 15.0}}) {
    const test::ReplayResult g = test::replay_capture(kCapture, "ssrt", c.index);
    ASSERT_TRUE(g.any && g.pooled.all.rde_defined) << c.level;
    // Every frame has an estimate: the first one is primed from the frame itself.
    ASSERT_EQ(g.light_error_deg.size(), 8u) << c.level;
    const double worst = *std::max_element(g.light_error_deg.begin(), g.light_error_deg.end());
    std::printf("ssrt %s: direction error median %.1f worst %.1f deg, RDE all %.3f real %.3f "
                "virtual %.3f\n", c.level, median(g.light_error_deg), worst, g.pooled.all.rde,
                g.pooled.real.rde, g.pooled.virtual_.rde);
    EXPECT_LT(median(g.light_error_deg), c.median_deg) << c.level;
    EXPECT_LT(worst, c.worst_deg) << c.level;
    EXPECT_LT(g.pooled.all.rde, base.pooled.all.rde) << c.level;
  }
}

// The priming run: ssrt's first frame is run twice (once to estimate, output dropped), so it is
// already lit by its own estimate; every frame still gives exactly one output, the first says
// so in its notes, and baseline (nothing to estimate) is never primed.
TEST(GoldenSsrt, FirstFrameIsPrimedOnceAndEveryFrameGivesOneOutput) {
  auto capture = CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160");
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  for (const char* technique : {"ssrt", "baseline"}) {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = technique;
    s.level = 3;
    auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure},
                             *capture->scene());
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    std::vector<FrameOutput> outs;
    for (size_t i = 0; i < capture->frame_count(); ++i) {
      auto f = capture->read_frame(i);
      ASSERT_TRUE(f.ok());
      f->index = int64_t(i);
      auto o = (*rt)->process(*f);
      ASSERT_TRUE(o.ok()) << o.error().message;
      for (auto& x : *o) outs.push_back(std::move(x));
    }
    auto rest = (*rt)->flush();
    ASSERT_TRUE(rest.ok()) << rest.error().message;
    for (auto& x : *rest) outs.push_back(std::move(x));
    ASSERT_EQ(outs.size(), capture->frame_count()) << technique;
    int primed = 0;
    for (size_t i = 0; i < outs.size(); ++i) {
      EXPECT_EQ(outs[i].stats.frame_index, int64_t(i)) << technique;
      for (const std::string& n : outs[i].stats.notes)
        if (n.find("primes") != std::string::npos) ++primed;
    }
    const bool ssrt = std::string(technique) == "ssrt";
    EXPECT_EQ(primed, ssrt ? 1 : 0) << technique;
    if (ssrt) {
      ASSERT_TRUE(outs[0].light.has_value());
      EXPECT_TRUE(outs[0].light->valid) << "frame 0 is lit by an estimate, not the prior";
    }
  }
}

}  // namespace
}  // namespace mrgi
