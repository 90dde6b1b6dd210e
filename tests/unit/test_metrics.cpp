#include <gtest/gtest.h>

#include <cmath>

#include "mrgi/metrics.h"

using namespace mrgi;

namespace {
ImageRGB8 filled(int w, int h, uint8_t v) { return ImageRGB8(w, h, v); }
}  // namespace

TEST(Metrics, IdenticalOutputHasZeroError) {
  ImageRGB8 c = filled(32, 16, 100), g = filled(32, 16, 100);
  for (int x = 0; x < 8; ++x) g.at(x, 3)[1] = 30;  // a shadow in the reference
  auto r = measure_error(g, c, g, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->all.rde_defined);
  EXPECT_DOUBLE_EQ(r->all.rde, 0.0);
  EXPECT_DOUBLE_EQ(r->all.rmse8, 0.0);
  EXPECT_NEAR(r->all.ssim, 1.0, 1e-9);
}

TEST(Metrics, CameraOnlyOutputHasRdeOne) {
  ImageRGB8 c = filled(32, 16, 120), g = c;
  for (int y = 4; y < 12; ++y)
    for (int x = 4; x < 20; ++x) g.at(x, y)[0] = g.at(x, y)[1] = g.at(x, y)[2] = 40;
  auto r = measure_error(c, c, g, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->all.rde, 1.0, 1e-12);
  EXPECT_GT(r->all.rmse8, 0.0);
  EXPECT_LT(r->all.ssim, 1.0);
}

TEST(Metrics, KnownOffsetGivesKnownRde) {
  // G-C = d everywhere (linear), O-C = d/2: RDE = ||d/2|| / ||d|| = 0.5 exactly in linear space.
  ImageRGB8 c = filled(8, 8, 0), g = filled(8, 8, 255), o = filled(8, 8, 188);
  const double half = srgb8_to_linear(188);
  auto r = measure_error(o, c, g, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->all.rde, 1.0 - half, 1e-9);
  EXPECT_NEAR(r->all.rde, 0.5, 0.01);
  EXPECT_NEAR(r->all.rmse8, 255.0 - 188.0, 1e-9);
}

TEST(Metrics, MaskSplitsRealAndVirtualPixels) {
  ImageRGB8 c = filled(4, 4, 50), g = c, o = c;
  ImageU8 mask(4, 4, 0);
  mask.at(0, 0)[0] = 255;
  g.at(0, 0)[0] = 200;  // virtual pixel differs in the reference, output got it right
  o.at(0, 0)[0] = 200;
  g.at(3, 3)[2] = 10;   // a real shadow pixel the output missed
  auto r = measure_error(o, c, g, &mask);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->virtual_.pixels, 1u);
  EXPECT_EQ(r->real.pixels, 15u);
  EXPECT_DOUBLE_EQ(r->virtual_.rde, 0.0);
  EXPECT_NEAR(r->real.rde, 1.0, 1e-12);
  EXPECT_GT(r->all.rde, 0.0);
  EXPECT_LT(r->all.rde, 1.0);
}

TEST(Metrics, NothingToChangeIsReportedUndefined) {
  ImageRGB8 c = filled(4, 4, 50), o = filled(4, 4, 60);
  auto r = measure_error(o, c, c, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->all.rde_defined);
  EXPECT_GT(r->all.delta_rms, 0.0);
  EXPECT_FALSE(std::isnan(r->all.rde));
}

TEST(Metrics, SizeMismatchIsRefusedWithSizes) {
  auto r = measure_error(filled(4, 4, 0), filled(4, 4, 0), filled(5, 4, 0), nullptr);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::BadInput);
  EXPECT_NE(r.error().message.find("5x4"), std::string::npos);
}

TEST(Metrics, RgbaOutputMatchesRgb) {
  ImageRGB8 c = filled(6, 6, 90), g = c;
  g.at(2, 2)[0] = 10;
  ImageRGBA8 o(6, 6, 90);
  auto r = measure_error(o, c, g, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->all.rde, 1.0, 1e-12);
}

TEST(Metrics, PoolingTwoFramesEqualsOneBigFrame) {
  ImageRGB8 c = filled(4, 2, 50), g1 = c, g2 = c, o = c;
  g1.at(0, 0)[0] = 200;
  g2.at(1, 1)[1] = 0;
  auto r1 = measure_error(o, c, g1, nullptr), r2 = measure_error(o, c, g2, nullptr);
  ASSERT_TRUE(r1.ok() && r2.ok());
  const ErrorFigures p = pool(r1->all, r2->all);
  EXPECT_EQ(p.pixels, 16u);
  EXPECT_NEAR(p.rde, 1.0, 1e-12);  // camera-only output on both frames
  EXPECT_NEAR(p.rmse8 * p.rmse8 * 16 * 3, r1->all.rmse8 * r1->all.rmse8 * 8 * 3 + r2->all.rmse8 * r2->all.rmse8 * 8 * 3, 1e-6);
}

TEST(Metrics, TheTruthSplitsRealPixelsIntoInfluencedAndRest) {
  // A 4x4 frame: one virtual pixel, one real pixel the truth darkens (a shadow, 100 -> 60 in one
  // channel), one it changes by a single 8-bit step (quantisation, not an effect), the rest equal.
  ImageRGB8 c = filled(4, 4, 100), g = c, o = c;
  ImageU8 mask(4, 4, 0);
  mask.at(0, 0)[0] = 255;
  g.at(0, 0)[1] = 180;
  g.at(1, 1)[0] = 60;   // the shadow
  g.at(2, 2)[0] = 101;  // one step: below three steps of noise
  o.at(1, 1)[0] = 80;   // the output darkens it half as much
  o.at(3, 3)[2] = 90;   // and darkens a pixel the truth leaves
  auto r = measure_error(o, c, g, &mask);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->influenced.pixels, 1u);
  EXPECT_EQ(r->rest.pixels, 14u);
  EXPECT_EQ(r->influenced.pixels + r->rest.pixels, r->real.pixels);
  // Signed sums of the change, linear: the output took less light from the shadow pixel than
  // the truth, and some from a pixel the truth did not touch.
  const double l100 = srgb8_to_linear(100), l80 = srgb8_to_linear(80), l60 = srgb8_to_linear(60),
               l90 = srgb8_to_linear(90), l101 = srgb8_to_linear(101);
  EXPECT_NEAR(r->influenced.change_sum, l80 - l100, 1e-9);
  EXPECT_NEAR(r->influenced.truth_change_sum, l60 - l100, 1e-9);
  EXPECT_NEAR(r->rest.change_sum, l90 - l100, 1e-9);
  EXPECT_NEAR(r->rest.truth_change_sum, l101 - l100, 1e-9);
  EXPECT_NEAR(r->real.change_sum, r->influenced.change_sum + r->rest.change_sum, 1e-12);
  EXPECT_TRUE(r->rest.rde_defined);  // the one-step pixel: something to compare against
  // Pooling keeps the sums.
  const RdeReport twice = pool(*r, *r);
  EXPECT_NEAR(twice.influenced.truth_change_sum, 2.0 * r->influenced.truth_change_sum, 1e-12);
  EXPECT_EQ(twice.rest.pixels, 28u);
}

// The influenced real pixels split by the sign of the truth's change: a shadow is `darkened`, a
// bleed of red light `brightened`; per-channel sums say which colour each has, the output's
// beside the truth's.
TEST(Metrics, TheTruthSplitsItsChangesIntoDarkenedAndBrightened) {
  ImageRGB8 c = filled(4, 4, 100), g = c, o = c;
  g.at(1, 1)[0] = g.at(1, 1)[1] = g.at(1, 1)[2] = 60;  // a grey shadow
  g.at(2, 2)[0] = 130;                                   // red bleeding onto a real wall
  g.at(2, 2)[2] = 95;                                    // (and a little blue light blocked)
  o.at(1, 1)[0] = o.at(1, 1)[1] = o.at(1, 1)[2] = 80;  // the output: a lighter shadow
  o.at(2, 2)[0] = 160;                                   // and too much red
  auto r = measure_error(o, c, g, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->darkened.pixels, 1u);
  EXPECT_EQ(r->brightened.pixels, 1u);
  EXPECT_EQ(r->darkened.pixels + r->brightened.pixels, r->influenced.pixels);
  const double l100 = srgb8_to_linear(100);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r->darkened.truth_change_rgb[k], srgb8_to_linear(60) - l100, 1e-9);
    EXPECT_NEAR(r->darkened.change_rgb[k], srgb8_to_linear(80) - l100, 1e-9);
  }
  EXPECT_NEAR(r->brightened.truth_change_rgb[0], srgb8_to_linear(130) - l100, 1e-9);
  EXPECT_NEAR(r->brightened.change_rgb[0], srgb8_to_linear(160) - l100, 1e-9);
  EXPECT_NEAR(r->brightened.truth_change_rgb[1], 0.0, 1e-12);
  EXPECT_NEAR(r->brightened.truth_change_rgb[2], srgb8_to_linear(95) - l100, 1e-9);
  EXPECT_NEAR(r->brightened.change_rgb[2], 0.0, 1e-12);  // the output missed the blocked blue
  // The channel sums add up to the total, and pooling keeps them.
  EXPECT_NEAR(r->brightened.change_rgb[0] + r->brightened.change_rgb[1] + r->brightened.change_rgb[2],
              r->brightened.change_sum, 1e-12);
  const RdeReport twice = pool(*r, *r);
  EXPECT_NEAR(twice.brightened.truth_change_rgb[0], 2.0 * r->brightened.truth_change_rgb[0], 1e-12);
  EXPECT_EQ(twice.darkened.pixels, 2u);
}

// The silhouette band: pixels within kSilhouetteBandPx (Euclidean) of the other side of the mask,
// on both sides; an error only there shows in the band's RDE and not outside it.
TEST(Metrics, TheSilhouetteBandIsTheMaskEdgeWithinTwoPixels) {
  const int w = 20, h = 20;
  ImageRGB8 c = filled(w, h, 100), g = c, o = c;
  ImageU8 mask(w, h, 0);
  for (int y = 8; y < 12; ++y)
    for (int x = 8; x < 12; ++x) mask.at(x, y)[0] = 255;  // a 4 x 4 virtual square
  size_t expected = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool v = mask.at(x, y)[0] != 0;
      bool edge = false;
      for (int yy = 0; yy < h; ++yy)
        for (int xx = 0; xx < w; ++xx)
          edge = edge || ((mask.at(xx, yy)[0] != 0) != v && (xx - x) * (xx - x) + (yy - y) * (yy - y) <= 4);
      expected += edge ? 1 : 0;
    }
  // The truth changes every pixel; the output is right everywhere but at one band pixel (the
  // square's corner) and one pixel far from it.
  for (auto& b : g.data) b = 60;
  o = g;
  o.at(8, 8)[0] = 200;   // on the edge
  o.at(1, 1)[0] = 200;   // outside the band
  auto r = measure_error(o, c, g, &mask);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->silhouette.pixels, expected);
  // Every pixel of the square (none is more than 2 from outside it) and the 36 real ones of its
  // dilation by a disc of radius 2 (rows of 4, 6, 8, 8, 8, 8, 6, 4 pixels less the 16 of the square).
  EXPECT_EQ(expected, 52u);
  const double d = double(srgb8_to_linear(200)) - double(srgb8_to_linear(60));
  EXPECT_NEAR(r->silhouette.err2, d * d, 1e-12);  // the edge pixel only
  EXPECT_NEAR(r->all.err2, 2.0 * d * d, 1e-12);
  // Without a mask there is no silhouette.
  auto no_mask = measure_error(o, c, g, nullptr);
  ASSERT_TRUE(no_mask.ok());
  EXPECT_EQ(no_mask->silhouette.pixels, 0u);
  // Pooling sums the band as the other sets.
  EXPECT_EQ(pool(*r, *r).silhouette.pixels, 2 * expected);
}
