// Importance sampling by hierarchical warping (mrgi_shared.h warp_step, gi/importance.h): each
// step's child probabilities sum to one and follow the importance; a pyramid's samples land on
// texels as often as their share of the importance (checked on 2^20 stratified samples), with
// the probability they report; zero images sample uniformly; bad sizes are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gi/importance.h"

namespace {
using namespace mrgi;

TEST(HierarchicalWarping, StepPicksChildrenByTheirImportance) {
  const glm::vec4 q(1.0f, 3.0f, 0.0f, 4.0f);  // (0,0), (1,0), (0,1), (1,1)
  const int n = 256;
  double hits[4] = {0, 0, 0, 0};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const shader::WarpStep s = shader::warp_step(glm::vec2((x + 0.5f) / n, (y + 0.5f) / n), q);
      ASSERT_GE(s.u.x, 0.0f);
      ASSERT_LT(s.u.x, 1.0f);
      ASSERT_GE(s.u.y, 0.0f);
      ASSERT_LT(s.u.y, 1.0f);
      const int k = s.child.y * 2 + s.child.x;
      const float want = q[k] / 8.0f;
      ASSERT_NEAR(s.probability, want, 1e-6f);
      hits[k] += 1.0;
    }
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(hits[k] / (n * n), q[k] / 8.0, 0.005) << "child " << k;
  // Nothing important: an even split.
  const shader::WarpStep z = shader::warp_step(glm::vec2(0.7f, 0.2f), glm::vec4(0.0f));
  EXPECT_EQ(z.child, glm::ivec2(1, 0));
  EXPECT_NEAR(z.probability, 0.25f, 1e-6f);
}

TEST(HierarchicalWarping, PyramidSamplesFollowTheImage) {
  // 6 x 5 (not a power of two), one bright texel, a dim band, zeros, a negative and a NaN.
  const int w = 6, h = 5;
  std::vector<float> img(size_t(w * h), 0.0f);
  for (int x = 0; x < w; ++x) img[size_t(2 * w + x)] = 0.5f;
  img[size_t(1 * w + 4)] = 10.0f;
  img[size_t(4 * w + 0)] = -3.0f;
  img[size_t(4 * w + 1)] = std::nanf("");
  double total = 0.0;
  for (float v : img) total += v > 0.0f && std::isfinite(v) ? v : 0.0f;
  auto p = gi::ImportancePyramid::create(w, h, img);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const int n = 1024;  // a stratified grid: each texel's region of u is hit in proportion to its area, to about 1 / n
  std::vector<double> hits(size_t(w * h), 0.0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const gi::ImportanceSample s = p->sample(glm::vec2((x + 0.5f) / n, (y + 0.5f) / n));
      ASSERT_GE(s.texel.x, 0);
      ASSERT_LT(s.texel.x, w);
      ASSERT_GE(s.texel.y, 0);
      ASSERT_LT(s.texel.y, h);
      ASSERT_GE(s.position.x, float(s.texel.x));
      ASSERT_LT(s.position.x, float(s.texel.x + 1));
      ASSERT_NEAR(s.probability, p->probability(s.texel), 1e-5f);
      hits[size_t(s.texel.y * w + s.texel.x)] += 1.0;
    }
  for (int i = 0; i < w * h; ++i) {
    const double want = (img[size_t(i)] > 0.0f && std::isfinite(img[size_t(i)]) ? img[size_t(i)] : 0.0) / total;
    EXPECT_NEAR(hits[size_t(i)] / (n * n), want, 0.002) << "texel " << i;
    if (want == 0.0) {
      EXPECT_EQ(hits[size_t(i)], 0.0) << "texel " << i << " has no importance";
    }
  }
}

TEST(HierarchicalWarping, ZeroImageIsUniformAndBadSizesAreRefused) {
  auto p = gi::ImportancePyramid::create(3, 3, std::vector<float>(9, 0.0f));
  ASSERT_TRUE(p.ok());
  EXPECT_TRUE(p->uniform());
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(p->probability(glm::ivec2(i % 3, i / 3)), 1.0f / 9.0f, 1e-6f);
  auto bad = gi::ImportancePyramid::create(3, 3, std::vector<float>(8, 1.0f));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("8 values for 3x3"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(gi::ImportancePyramid::create(0, 3, {}).ok());
}

}  // namespace
