// shade_direct's split of the image (shading/shade_dispatch.h): every pixel in exactly one
// dispatch, every pixel of the objects' bounds in the general one, for bounds anywhere (inside,
// at each edge, the whole image, outside), none (real-only everywhere) and unknown (general).
#include <gtest/gtest.h>

#include <vector>

#include "shading/shade_dispatch.h"

namespace mrgi::shading {
namespace {

void expect_partition(VkExtent2D e, const std::optional<VkRect2D>& area) {
  std::vector<int> hits(size_t(e.width) * e.height, 0), general(size_t(e.width) * e.height, 0);
  for (const ShadeDispatch& d : shade_dispatches(e, area)) {
    ASSERT_LE(d.rect.z, int(e.width));
    ASSERT_LE(d.rect.w, int(e.height));
    for (int y = d.rect.y; y < d.rect.w; ++y)
      for (int x = d.rect.x; x < d.rect.z; ++x) {
        ++hits[size_t(y) * e.width + x];
        general[size_t(y) * e.width + x] += d.real_only ? 0 : 1;
      }
  }
  for (uint32_t y = 0; y < e.height; ++y)
    for (uint32_t x = 0; x < e.width; ++x) {
      ASSERT_EQ(hits[size_t(y) * e.width + x], 1) << "pixel " << x << "," << y;
      const bool in_area = !area || (int(x) >= area->offset.x && int(x) < area->offset.x + int(area->extent.width) &&
                                     int(y) >= area->offset.y && int(y) < area->offset.y + int(area->extent.height));
      if (in_area) {
        ASSERT_EQ(general[size_t(y) * e.width + x], 1) << "virtual-capable pixel " << x << "," << y;
      }
    }
}

TEST(ShadeDispatch, EveryPixelOnceAndTheObjectsBoundsInTheGeneralVariant) {
  const VkExtent2D e{83, 61};
  expect_partition(e, std::nullopt);
  expect_partition(e, VkRect2D{{0, 0}, {0, 0}});
  expect_partition(e, VkRect2D{{10, 7}, {21, 13}});
  expect_partition(e, VkRect2D{{0, 0}, {83, 61}});
  expect_partition(e, VkRect2D{{0, 20}, {5, 5}});
  expect_partition(e, VkRect2D{{78, 55}, {5, 6}});
  expect_partition(e, VkRect2D{{40, 0}, {3, 61}});
  expect_partition(e, VkRect2D{{1, 1}, {1, 1}});
}

TEST(ShadeDispatch, NoObjectIsRealOnlyAndUnknownBoundsAreGeneral) {
  const auto none = shade_dispatches({64, 48}, VkRect2D{{0, 0}, {0, 0}});
  ASSERT_EQ(none.size(), 1u);
  EXPECT_TRUE(none[0].real_only);
  const auto unknown = shade_dispatches({64, 48}, std::nullopt);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_FALSE(unknown[0].real_only);
  // The general rectangle starts and ends on workgroup edges (8 x 8) inside the image.
  const auto some = shade_dispatches({640, 480}, VkRect2D{{101, 53}, {90, 77}});
  EXPECT_EQ(some[0].rect.x % 8, 0);
  EXPECT_EQ(some[0].rect.y % 8, 0);
  EXPECT_EQ(some[0].rect.z % 8, 0);
  EXPECT_EQ(some[0].rect.w % 8, 0);
  EXPECT_EQ(some.size(), 5u);
}

}  // namespace
}  // namespace mrgi::shading
