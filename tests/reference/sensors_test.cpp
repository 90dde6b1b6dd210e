// Sensor models: Kinect-like depth (quantisation, noise growth, holes, range) and the camera.
#include <gtest/gtest.h>

#include <cmath>

#include "mrgi/reference/sensors.h"

namespace mrgi::reference {
namespace {

DepthSensorSettings quiet() {
  DepthSensorSettings s;
  s.axial_noise = false;
  return s;
}

// Disparity steps of 1/8 px: at depth z the step in depth is z^2 / (8 f b).
TEST(KinectDepth, QuantisesInDisparityWithStepsGrowingWithDepthSquared) {
  const DepthSensorSettings s = quiet();
  for (double z : {0.8, 1.5, 3.0}) {
    // Sweep finely and collect the distinct output depths around z.
    double prev = kinect_quantise(s, z), step = 0.0;
    for (double zz = z; zz < z + 0.2; zz += 1e-5) {
      const double q = kinect_quantise(s, zz);
      if (q != prev) {
        step = q - prev;
        break;
      }
    }
    const double expected = z * z / (8.0 * 580.0 * 0.075);
    EXPECT_NEAR(step, expected, 0.08 * expected) << "z " << z;
  }
  EXPECT_NEAR(kinect_quantise(s, 1.0), 1.0, 0.002);
}

TEST(KinectDepth, NoiseStandardDeviationFollowsTheModel) {
  DepthSensorSettings s;
  s.disparity_step_px = 0.0;  // noise alone
  s.edge_jump_m = 0.0;
  const int w = 200, h = 100;
  double previous_sigma = 0.0;
  for (double z : {0.6, 1.5, 2.5, 3.5}) {
    std::vector<float> depth(size_t(w) * h, float(z)), cosine(size_t(w) * h, 1.0f);
    const ImageU16 out = depth_frame(depth, cosine, w, h, s, 7, 0).value();
    double sum = 0.0, sum2 = 0.0;
    for (uint16_t v : out.data) {
      const double m = v / s.depth_scale - z;
      sum += m;
      sum2 += m * m;
    }
    const double n = double(out.data.size());
    const double sigma = std::sqrt(sum2 / n - (sum / n) * (sum / n));
    const double expected = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
    EXPECT_NEAR(sigma, expected, 0.05 * expected + 1.0 / s.depth_scale) << "z " << z;
    EXPECT_NEAR(sum / n, 0.0, 0.2 * expected);
    EXPECT_GT(sigma, previous_sigma);
    previous_sigma = sigma;
  }
}

TEST(KinectDepth, RangeLimitsGiveNoMeasurement) {
  const DepthSensorSettings s = quiet();
  std::vector<float> depth = {0.3f, 0.5f, 3.9f, 4.2f}, cosine(4, 1.0f);
  DepthSensorSettings no_edges = s;
  no_edges.edge_jump_m = 0.0;
  const ImageU16 out = depth_frame(depth, cosine, 4, 1, no_edges, 1, 0).value();
  EXPECT_EQ(out.data[0], 0);
  EXPECT_GT(out.data[1], 0);
  EXPECT_GT(out.data[2], 0);
  EXPECT_EQ(out.data[3], 0);
}

TEST(KinectDepth, HolesAtDepthEdgesAndGrazingAngles) {
  DepthSensorSettings s = quiet();
  s.edge_hole_radius_px = 1;
  const int w = 20, h = 10;
  std::vector<float> depth(size_t(w) * h, 1.0f), cosine(size_t(w) * h, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 10; x < w; ++x) depth[size_t(y) * w + x] = 2.0f;  // a step edge at x = 10
  cosine[size_t(5) * w + 3] = std::cos(80.0f * 3.14159265f / 180.0f);  // grazing pixel
  cosine[size_t(5) * w + 4] = std::cos(70.0f * 3.14159265f / 180.0f);  // steep but measurable
  const ImageU16 out = depth_frame(depth, cosine, w, h, s, 1, 0).value();
  auto at = [&](int x, int y) { return out.data[size_t(y) * w + x]; };
  for (int y = 0; y < h; ++y) {
    for (int x : {8, 9, 10, 11}) EXPECT_EQ(at(x, y), 0) << x << "," << y;  // edge pixels + radius 1
    EXPECT_GT(at(7, y), 0);
    EXPECT_GT(at(12, y), 0);
  }
  EXPECT_EQ(at(3, 5), 0);
  EXPECT_GT(at(4, 5), 0);
  EXPECT_NEAR(at(0, 0) / s.depth_scale, 1.0, 0.003);
}

TEST(KinectDepth, RefusesBadSettings) {
  DepthSensorSettings s;
  s.depth_scale = 50000.0;  // 4 m * 50000 does not fit 16 bits
  std::vector<float> d(4, 1.0f), c(4, 1.0f);
  EXPECT_FALSE(depth_frame(d, c, 2, 2, s, 1, 0).ok());
  EXPECT_FALSE(depth_frame(d, c, 3, 2, DepthSensorSettings{}, 1, 0).ok());  // wrong buffer size
}

TEST(CameraModel, ResponseIsSrgbOfExposedRadiance) {
  ImageRGBF radiance(3, 1);
  radiance.data = {0.0f, 0.0f, 0.0f, 0.1f, 0.1f, 0.1f, 5.0f, 5.0f, 5.0f};
  const ImageRGB8 img = camera_frame(radiance, 2.0, {}, 1, 0).value();
  EXPECT_EQ(img.data[0], 0);
  // 0.2 linear -> sRGB 0.4845 -> 124
  EXPECT_EQ(img.data[3], 124);
  EXPECT_EQ(img.data[6], 255);  // saturated
  EXPECT_FALSE(camera_frame(radiance, 0.0, {}, 1, 0).ok());
}

// Shot noise grows with the signal; the same (seed, frame) gives the same noise realisation, so
// two images that differ only in one pixel stay identical everywhere else.
TEST(CameraModel, NoiseIsSharedBetweenCameraAndReference) {
  const int w = 64, h = 64;
  ImageRGBF a(w, h, 0.2f), b(w, h, 0.2f);
  b.data[0] = 0.8f;
  CameraNoiseSettings noise;
  noise.full_well_electrons = 2000.0;
  noise.read_noise_electrons = 5.0;
  const ImageRGB8 ca = camera_frame(a, 1.0, noise, 3, 5).value();
  const ImageRGB8 cb = camera_frame(b, 1.0, noise, 3, 5).value();
  const ImageRGB8 other_frame = camera_frame(a, 1.0, noise, 3, 6).value();
  EXPECT_NE(ca.data[0], cb.data[0]);
  EXPECT_TRUE(std::equal(ca.data.begin() + 3, ca.data.end(), cb.data.begin() + 3));
  EXPECT_NE(ca.data, other_frame.data);
  // The noise is visible: not every pixel of a flat field has the same value.
  int distinct = 0;
  for (size_t i = 1; i < ca.data.size(); ++i) distinct += ca.data[i] != ca.data[0];
  EXPECT_GT(distinct, 100);
}

}  // namespace
}  // namespace mrgi::reference
