// dvct's volume region (gi/voxelize.h doubled_box_region, paper Sec. 3.4): the doubled bounding
// box of the virtual object, as the cube the volumes are.
#include <gtest/gtest.h>

#include "gi/voxelize.h"

namespace {
using mrgi::gi::doubled_box_region;

TEST(VoxelRegion, IsTheDoubledBoxAsACubeAroundItsCentre) {
  // A box 0.2 x 0.4 x 0.1 m: a cube of 0.8 m around its centre, 64 voxels of 12.5 mm.
  const auto r = doubled_box_region(glm::vec3(1.0f, 0.0f, -0.1f), glm::vec3(1.2f, 0.4f, 0.0f), 64, 0.05f);
  EXPECT_FLOAT_EQ(r.voxel_size, 0.8f / 64.0f);
  EXPECT_NEAR(r.origin.x, 1.1f - 0.4f, 1e-6f);
  EXPECT_NEAR(r.origin.y, 0.2f - 0.4f, 1e-6f);
  EXPECT_NEAR(r.origin.z, -0.05f - 0.4f, 1e-6f);
  // The box sits in the middle half of the cube on its longest axis.
  EXPECT_NEAR(0.0f - r.origin.y, 0.2f, 1e-6f);
}

TEST(VoxelRegion, AFlatOrEmptyBoxGetsTheMinimumSide) {
  const auto flat = doubled_box_region(glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 0.0f), 32, 0.5f);
  EXPECT_FLOAT_EQ(flat.voxel_size, 0.5f / 32.0f);
  EXPECT_FLOAT_EQ(flat.origin.x, -0.25f);
  // An inverted box (nothing in it) does not make a negative size.
  const auto inverted = doubled_box_region(glm::vec3(1.0f), glm::vec3(-1.0f), 32, 0.5f);
  EXPECT_GT(inverted.voxel_size, 0.0f);
}

}  // namespace
