// Temporal stability (mrgi/perf/temporal.h): the frame-to-frame change of the delta on static
// real pixels, with the camera still and moving, the truth's beside it, and bad sizes refused.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "mrgi/metrics.h"
#include "mrgi/perf/temporal.h"

namespace {
using namespace mrgi;

// 64 x 48 pixels, focal 60 px, pixel-centre principal point.
Intrinsics small_camera() { return Intrinsics{64, 48, 60.0, 60.0, 31.5, 23.5}; }

// A frame looking at a wall 1 m away (depth_scale 1000), the camera at world x = `x`; the
// output darkens (to 80 from 100) the wall where world x is in [0, 0.2] m.
struct Frame {
  ImageRGB8 camera, reference;
  ImageRGBA8 output;
  ImageU16 depth;
  perf::StabilityFrame view(bool with_reference) const {
    perf::StabilityFrame f;
    f.camera = &camera;
    f.output = &output;
    f.reference = with_reference ? &reference : nullptr;
    f.depth = &depth;
    f.camera_to_world = glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0.0, 0.0));
    return f;
  }
  double x = 0.0;
};

Frame wall_frame(double x, uint8_t band, uint8_t truth_band) {
  const Intrinsics k = small_camera();
  Frame f;
  f.x = x;
  f.camera = ImageRGB8(k.width, k.height);
  f.reference = ImageRGB8(k.width, k.height);
  f.output = ImageRGBA8(k.width, k.height);
  f.depth = ImageU16(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const size_t i = size_t(v) * size_t(k.width) + size_t(u);
      const double world_x = (u - k.cx) / k.fx + x;
      const bool in_band = world_x >= 0.0 && world_x <= 0.2;
      for (int c = 0; c < 3; ++c) {
        f.camera.data[i * 3 + c] = 100;
        f.reference.data[i * 3 + c] = in_band ? truth_band : 100;
        f.output.data[i * 4 + c] = in_band ? band : 100;
      }
      f.output.data[i * 4 + 3] = 255;
      f.depth.data[i] = 1000;
    }
  return f;
}

TEST(TemporalStability, StillCameraMeasuresTheChangeOfTheDelta) {
  const Frame a = wall_frame(0.0, 80, 80), b = wall_frame(0.0, 80, 80), c = wall_frame(0.0, 90, 80);
  auto same = perf::delta_stability(a.view(true), b.view(true), small_camera(), 1000.0);
  ASSERT_TRUE(same.ok()) << same.error().message;
  EXPECT_EQ(same->pixels, size_t(64 * 48));
  EXPECT_NEAR(same->output_change, 0.0, 1e-12);
  EXPECT_TRUE(same->has_truth);
  EXPECT_NEAR(same->truth_change, 0.0, 1e-12);
  // The band lightens from 80 to 90: the band's share of the pixels times the step.
  auto lighter = perf::delta_stability(a.view(true), c.view(true), small_camera(), 1000.0);
  ASSERT_TRUE(lighter.ok());
  size_t band = 0;
  for (int u = 0; u < 64; ++u) band += ((u - 31.5) / 60.0 >= 0.0 && (u - 31.5) / 60.0 <= 0.2) ? 1 : 0;
  const double step = srgb8_to_linear(90) - srgb8_to_linear(80);
  EXPECT_NEAR(lighter->output_change, step * double(band) / 64.0, 1e-9);
  EXPECT_NEAR(lighter->truth_change, 0.0, 1e-12);
}

TEST(TemporalStability, AMovingCameraComparesTheSameSurface) {
  // The camera moves 0.1 m along x; the darkened band stays on the wall, so reprojected the
  // delta does not change (to the band's edges, one pixel of rounding), where the same pixel
  // of the two frames would differ over the 6 pixels the band moved.
  const Frame a = wall_frame(0.0, 80, 80), b = wall_frame(0.1, 80, 80);
  auto r = perf::delta_stability(a.view(false), b.view(false), small_camera(), 1000.0);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->has_truth);
  EXPECT_GT(r->pixels, size_t(64 * 48 * 8 / 10));  // all but the 6 columns that left the view
  const double step = srgb8_to_linear(100) - srgb8_to_linear(80);
  EXPECT_LT(r->output_change, step * 2.0 / 64.0);      // at most a column of each edge
  EXPECT_GT(step * 12.0 / 64.0, 2.0 * r->output_change);  // what comparing pixel for pixel gives
}

TEST(TemporalStability, VirtualPixelsAndBadInputs) {
  Frame a = wall_frame(0.0, 80, 80), b = wall_frame(0.0, 90, 80);
  ImageU8 mask(64, 48, 255);  // everything virtual: nothing to compare
  perf::StabilityFrame va = a.view(true), vb = b.view(true);
  vb.virtual_mask = &mask;
  auto none = perf::delta_stability(va, vb, small_camera(), 1000.0);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->pixels, 0u);
  EXPECT_EQ(none->output_change, 0.0);
  ImageU16 wrong(32, 24);
  vb = b.view(true);
  vb.depth = &wrong;
  auto bad = perf::delta_stability(va, vb, small_camera(), 1000.0);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("depth is 32x24"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(perf::delta_stability(va, a.view(true), small_camera(), 0.0).ok());
}

}  // namespace
