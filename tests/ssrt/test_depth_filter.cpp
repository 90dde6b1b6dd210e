// The ssrt depth filter chain D', D'', D''' (paper eq. 1-5), CPU reference, on constructed
// images where each case of eq. 3 and each filter's purpose can be checked.
#include <gtest/gtest.h>

#include <cmath>

#include "technique/ssrt/depth_filter.h"

namespace {
using namespace mrgi;
using namespace mrgi::ssrt;

struct Images {
  uint32_t w = 32, h = 32;
  std::vector<float> dc, dv, ic;
  Images(float d_c, float d_v, float i) : dc(w * h, d_c), dv(w * h, d_v), ic(w * h, i) {}
  float& at(std::vector<float>& v, uint32_t x, uint32_t y) { return v[y * w + x]; }
  DepthFilterInput input() { return {w, h, dc.data(), dv.data(), ic.data()}; }
};

TEST(SsrtDepthFilter, WindowReading) {
  EXPECT_EQ(window_side(20), 21u);
  EXPECT_EQ(window_side(8), 9u);
  EXPECT_EQ(window_side(2), 3u);
  EXPECT_EQ(window_stride(21, 5), 5u);
  EXPECT_EQ(window_stride(9, 5), 2u);
  EXPECT_EQ(window_stride(3, 5), 1u);
}

TEST(SsrtDepthFilter, MergeTakesVolumeWhereItAgreesAndCameraWhereSceneChanged) {
  Images im(1.00f, 1.02f, 100.0f);
  // A moved object: the camera sees it at 0.6 m, the lagging volume still has the wall.
  for (uint32_t y = 10; y < 20; ++y)
    for (uint32_t x = 10; x < 20; ++x) im.at(im.dc, x, y) = 0.6f;
  auto out = filter_depth_reference(im.input(), {});
  ASSERT_TRUE(out.ok()) << out.error().message;
  EXPECT_FLOAT_EQ(out->merged[2 * 32 + 2], 1.02f);   // case 2: within lambda_D -> D_v
  EXPECT_FLOAT_EQ(out->merged[15 * 32 + 15], 0.6f);  // case 1: beyond lambda_D -> D_c
}

TEST(SsrtDepthFilter, HolesFilledFromVolumeOrFromTheSameColourSide) {
  // Left half dark at 1 m, right half bright at 2 m; the volume agrees on the left only.
  Images im(0.0f, 0.0f, 0.0f);
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      const bool left = x < 16;
      im.at(im.dc, x, y) = left ? 1.0f : 2.0f;
      im.at(im.dv, x, y) = left ? 1.01f : 3.0f;
      im.at(im.ic, x, y) = left ? 20.0f : 200.0f;
    }
  // Holes on either side of the colour edge.
  im.at(im.dc, 14, 16) = 0.0f;
  im.at(im.dc, 17, 16) = 0.0f;
  auto out = filter_depth_reference(im.input(), {});
  ASSERT_TRUE(out.ok());
  // Case 3: most same-colour neighbours agree with the volume -> D_v.
  EXPECT_FLOAT_EQ(out->merged[16 * 32 + 14], 1.01f);
  // Case 4: the volume disagrees -> median of the same-colour neighbours, never the other side.
  EXPECT_FLOAT_EQ(out->merged[16 * 32 + 17], 2.0f);
}

TEST(SsrtDepthFilter, BilateralMedianRemovesSpikesButKeepsColourEdges) {
  Images im(0.0f, 0.0f, 0.0f);
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      im.at(im.dc, x, y) = x < 16 ? 1.0f : 2.0f;
      im.at(im.ic, x, y) = x < 16 ? 20.0f : 200.0f;
    }
  im.at(im.dc, 8, 8) = 1.5f;  // a spike inside the dark region
  auto out = filter_depth_reference(im.input(), {});
  ASSERT_TRUE(out.ok());
  EXPECT_FLOAT_EQ(out->merged[8 * 32 + 8], 1.5f);  // D' keeps measured depth (no volume)
  EXPECT_FLOAT_EQ(out->bilateral[8 * 32 + 8], 1.0f);
  // Right at the edge the joint median keeps each side's depth.
  EXPECT_FLOAT_EQ(out->bilateral[16 * 32 + 15], 1.0f);
  EXPECT_FLOAT_EQ(out->bilateral[16 * 32 + 16], 2.0f);
}

TEST(SsrtDepthFilter, FinalMedianCleansSinglePixelNoiseAndCanBeSwitchedOff) {
  Images im(1.0f, 0.0f, 50.0f);
  // D'' cannot see this outlier's colour neighbours (different intensity), D''' can.
  im.at(im.dc, 5, 5) = 3.0f;
  im.at(im.ic, 5, 5) = 250.0f;
  auto out = filter_depth_reference(im.input(), {});
  ASSERT_TRUE(out.ok());
  EXPECT_FLOAT_EQ(out->bilateral[5 * 32 + 5], 3.0f);
  EXPECT_FLOAT_EQ(out->final[5 * 32 + 5], 1.0f);
  DepthFilterSettings fast;
  fast.final_pass = false;
  auto out2 = filter_depth_reference(im.input(), fast);
  ASSERT_TRUE(out2.ok());
  EXPECT_EQ(out2->final, out2->bilateral);
}

TEST(SsrtDepthFilter, AllMissingDepthAndNoVolumeStayMissingWithoutNaN) {
  Images im(0.0f, 0.0f, 10.0f);
  DepthFilterInput in = im.input();
  in.depth_volume = nullptr;
  auto out = filter_depth_reference(in, {});
  ASSERT_TRUE(out.ok());
  for (float d : out->final) EXPECT_EQ(d, 0.0f);
  // NaN and Inf depth count as missing.
  Images bad(NAN, INFINITY, 10.0f);
  auto out2 = filter_depth_reference(bad.input(), {});
  ASSERT_TRUE(out2.ok());
  for (float d : out2->final) EXPECT_EQ(d, 0.0f);
}

TEST(SsrtDepthFilter, BadSettingsAndInputsAreRefused) {
  DepthFilterSettings s;
  s.depth_threshold_m = -1.0f;
  Images im(1.0f, 1.0f, 1.0f);
  auto r = filter_depth_reference(im.input(), s);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(r.error().message.find("depth_threshold_m"), std::string::npos);
  DepthFilterInput in = im.input();
  in.intensity = nullptr;
  auto r2 = filter_depth_reference(in, {});
  ASSERT_FALSE(r2.ok());
  EXPECT_EQ(r2.error().kind, ErrorKind::BadInput);
}

}  // namespace
