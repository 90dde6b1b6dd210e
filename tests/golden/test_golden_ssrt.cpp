// ssrt against the path-traced reference on the suite's environment-lit scene (perf/suite/
// env_fisheye: 640x480, 8 frames, 512 spp, courtyard HDR with a sun 34 degrees up behind the
// camera), validation layers on. The probeless estimate's
// dominant direction is compared with the band-1 direction of each frame's environment image,
// and the pooled RDE with `baseline`'s when baseline too lights the scene from each frame alone
// (the light stage's probeless estimate from the current view, scene.json's environment
// dropped): both then know only what the view shows, and ssrt adds what baseline lacks (soft SH
// shadows, one bounce). baseline given the environment image itself (importance-sampled lights
// with shadow maps) and baseline with the stage's estimate kept over the views (the default:
// 0.590 here against 0.762 from each view alone, better than ssrt fastest's 0.62) are printed
// beside it: they know more of the light, so they are bars for the estimate, not for the technique.
//
// Bounds: measured on lavapipe plus a margin. fast: direction 8.5 median / 9.0 worst
// degrees, RDE 0.583; fastest: 7.4 / 7.8 degrees, RDE 0.618. baseline high with the
// environment image: 0.517 (0.629 with a constant ambient in place of its importance-sampled
// lights); with the probeless estimate, see the printout.
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

// Every frame of `capture` through a runtime made with `s` (validation layers as `s` says), the
// outputs in frame order as they come back.
TEST(GoldenSsrt, EnvFisheyeLightDirectionAndRdeBeatBaseline) {
  const test::ReplayResult lit = test::replay_capture(kCapture, "baseline", 0);
  ASSERT_TRUE(lit.any && lit.pooled.all.rde_defined);
  std::printf("baseline high, environment image: RDE all %.3f real %.3f virtual %.3f\n", lit.pooled.all.rde,
              lit.pooled.real.rde, lit.pooled.virtual_.rde);
  const test::ReplayResult kept = test::replay_capture(kCapture, "baseline", 0, true);
  ASSERT_TRUE(kept.any && kept.pooled.all.rde_defined);
  std::printf("baseline high, probeless estimate kept over the views: RDE all %.3f real %.3f virtual %.3f, "
              "direction error median %.1f deg\n", kept.pooled.all.rde, kept.pooled.real.rde,
              kept.pooled.virtual_.rde, median(kept.light_error_deg));
  const test::ReplayResult base = test::replay_capture(kCapture, "baseline", 0, true, false);
  ASSERT_TRUE(base.any && base.pooled.all.rde_defined);
  std::printf("baseline high, probeless estimate of each view: RDE all %.3f real %.3f virtual %.3f, direction "
              "error median %.1f deg\n", base.pooled.all.rde, base.pooled.real.rde, base.pooled.virtual_.rde,
              median(base.light_error_deg));
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
  for (const char* technique : {"ssrt", "baseline"}) {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = technique;
    s.level = 3;
    std::vector<FrameOutput> outs;
    test::run_every_frame(*capture, s, outs);
    if (HasFatalFailure()) return;
    ASSERT_EQ(outs.size(), capture->frame_count()) << technique;
    int primed = 0;
    for (size_t i = 0; i < outs.size(); ++i) {
      EXPECT_EQ(outs[i].stats.frame_index, int64_t(i)) << technique;
      for (const std::string& n : outs[i].stats.notes)
        if (n.find("primed") != std::string::npos) ++primed;
    }
    const bool ssrt = std::string(technique) == "ssrt";
    EXPECT_EQ(primed, ssrt ? 1 : 0) << technique;
    if (ssrt) {
      ASSERT_TRUE(outs[0].light.has_value());
      EXPECT_TRUE(outs[0].light->valid) << "frame 0 is lit by an estimate, not the prior";
    }
  }
}

// The fast level at the camera's size composes its tiles in its shade pass (RuntimeSettings::
// fuse_compose); the runtime's compose pass, with the same formula, must give the same frames
// to 1/255 (the fused path keeps the solutions in 32-bit floats, compose reads them back from
// RGBA16F), the same virtual mask, and frames that differ from the camera where virtual light
// falls. Validation layers on.
TEST(GoldenSsrt, FusedComposeMatchesTheComposePass) {
  auto capture = CaptureReader::open(std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160");
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  std::vector<FrameOutput> runs[2];
  for (int fused = 0; fused < 2; ++fused) {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = "ssrt";
    s.level = 2;  // fast: 4x4 cells, tiled shade
    s.fuse_compose = fused == 1;
    test::run_every_frame(*capture, s, runs[fused]);
    if (HasFatalFailure()) return;
    ASSERT_EQ(runs[fused].size(), capture->frame_count());
  }
  size_t differing = 0, changed = 0, total = 0, fused_frames = 0;
  for (size_t i = 0; i < runs[0].size(); ++i) {
    const FrameOutput& a = runs[0][i];
    const FrameOutput& b = runs[1][i];
    ASSERT_EQ(a.image.data.size(), b.image.data.size());
    EXPECT_EQ(a.virtual_mask.data, b.virtual_mask.data) << "frame " << i;
    auto camera = capture->read_frame(i);
    ASSERT_TRUE(camera.ok());
    for (size_t p = 0; p < a.image.data.size() / 4; ++p) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(a.image.data[4 * p + c]) - int(b.image.data[4 * p + c])));
      ASSERT_LE(worst, 1) << "frame " << i << " pixel " << p;
      differing += worst > 0;
      for (int c = 0; c < 3; ++c) changed += b.image.data[4 * p + c] != camera->color.data[3 * p + c] ? 1 : 0;
      ++total;
    }
    bool compose_pass = false;
    for (const PassTiming& t : a.stats.passes) compose_pass |= t.name == "compose";
    EXPECT_TRUE(compose_pass) << "frame " << i << ": compose runs when fusing is off";
    bool notes_fused = false;
    for (const std::string& n : b.stats.skipped) notes_fused |= n.rfind("compose: ssrt_shade_tiled composes", 0) == 0;
    fused_frames += notes_fused;
  }
  EXPECT_EQ(fused_frames, runs[1].size()) << "every fused frame says compose ran no pass";
  EXPECT_LT(differing, total / 20) << "pixels 1/255 apart";
  EXPECT_GT(changed, total / 100) << "the virtual objects change the frame";
}

}  // namespace
}  // namespace mrgi
