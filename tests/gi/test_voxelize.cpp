// Surface voxelisation into a visibility volume (runtime/src/gi/voxelize.h) on lavapipe with
// validation: occupancy where a surface is and nowhere else, the mean normal, the mip chain's
// occupancy fractions (Sec. 3.2, Fig. 1 a), no triangles across the reconstruction's depth edges.
#include <glm/gtc/packing.hpp>

#include <cmath>
#include <optional>
#include <vector>

#include "gi/voxelize.h"
#include "volume_readback.h"
#include "vulkan/vk_test_util.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kN = 16;
constexpr float kVoxel = 0.1f;

struct Vertex {
  glm::vec3 position, normal;
  glm::vec2 uv{0.0f};
};

struct Rig {
  std::unique_ptr<gpu::FrameGraph> graph;
  std::optional<gi::Voxelizer> vox;
  gpu::BufferHandle readback;

  explicit Rig(gpu::Context& ctx) {
    graph = test::make_block_graph(ctx);
    gi::VoxelizeSettings s;
    s.name = "test voxels";
    s.resolution = kN;
    auto v = gi::Voxelizer::create(*graph, s);
    EXPECT_TRUE(v.ok()) << v.error().message;
    vox.emplace(std::move(*v));
    vox->set_region({glm::vec3(0.0f), kVoxel});
    readback = test::make_volume_readback(*graph, kN);
  }

  gpu::BufferHandle buffer(const std::string& name, const void* data, size_t bytes) {
    gpu::BufferDesc bd;
    bd.name = name;
    bd.size = bytes;
    auto h = graph->create_buffer(bd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(h.ok());
    EXPECT_TRUE(graph->context().upload_buffer(graph->gpu_buffer(*h, 0), data, bytes).ok());
    return *h;
  }

  // One frame: what `add` records between clear and resolve; returns levels 0 and 1 as RGBA.
  std::vector<std::vector<glm::vec4>> run(const std::function<void()>& add) {
    return test::run_and_read_volume(*graph, vox->volume().image(0), readback, kN, [&] {
      vox->add_clear(*graph);
      add();
      vox->add_resolve(*graph);
    });
  }
};

size_t at(uint32_t x, uint32_t y, uint32_t z, uint32_t n = kN) { return (size_t(z) * n + y) * n + x; }

// A square in the plane y = height from (x0, z0) to (x1, z1), its vertex normals `up`.
std::vector<Vertex> square(float height, float x0, float x1, float z0, float z1, glm::vec3 up) {
  return {{{x0, height, z0}, up}, {{x1, height, z0}, up}, {{x1, height, z1}, up}, {{x0, height, z1}, up}};
}

TEST_F(VulkanTest, VoxelizeMarksTheVoxelsASurfaceCrossesWithItsNormal) {
  Rig rig(ctx());
  // A floor square at y 0.55 (voxel row 5) over x, z in [0.2, 1.2]: voxels 2..11; its vertex
  // normals point down, so the stored normal does.
  const auto verts = square(0.55f, 0.2f, 1.2f, 0.2f, 1.2f, glm::vec3(0, -1, 0));
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
  const auto vb = rig.buffer("square vertices", verts.data(), verts.size() * sizeof(Vertex));
  const auto ib = rig.buffer("square indices", idx.data(), idx.size() * 4);
  auto levels = rig.run([&] { rig.vox->add_mesh(*rig.graph, "square", vb, ib, {{0, 6, 0}}); });
  int wrong = 0;
  for (uint32_t z = 0; z < kN; ++z)
    for (uint32_t y = 0; y < kN; ++y)
      for (uint32_t x = 0; x < kN; ++x) {
        const glm::vec4 v = levels[0][at(x, y, z)];
        const bool inside = y == 5 && x >= 2 && x <= 11 && z >= 2 && z <= 11;
        const glm::vec4 want = inside ? glm::vec4(0, -1, 0, 1) : glm::vec4(0.0f);
        for (int k = 0; k < 4; ++k) wrong += std::abs(v[k] - want[k]) > 1e-3f;
      }
  EXPECT_EQ(wrong, 0) << "voxel components off the square's occupancy and normal";
  // Level 1: a cell over y 4..5 holds 4 of its 8 sub-voxels: occlusion 0.5, normal x 0.5.
  const glm::vec4 coarse = levels[1][at(2, 2, 2, kN / 2)];
  EXPECT_NEAR(coarse.w, 0.5f, 1e-3f);
  EXPECT_NEAR(coarse.y, -0.5f, 1e-3f);
  EXPECT_EQ(levels[1][at(2, 3, 2, kN / 2)], glm::vec4(0.0f));
}

TEST_F(VulkanTest, VoxelizeCoversALargeTriangleWithoutHoles) {
  Rig rig(ctx());
  // One triangle 6.4 m across (64 voxels: the most sampled at half a voxel, kMaxSplit) holding
  // the whole region's layer y 0.85 (row 8), given as the second of two draw ranges (its
  // vertices after a vertex offset): ranges are voxelised in one pass, offsets honoured.
  std::vector<Vertex> verts = {{{-0.5f, 0.85f, -0.5f}, {0, 1, 0}}, {{4.0f, 0.85f, -0.5f}, {0, 1, 0}},
                               {{-0.5f, 0.85f, 4.0f}, {0, 1, 0}}};
  verts.insert(verts.begin(), 3, Vertex{{50.0f, 50.0f, 50.0f}, {0, 1, 0}});  // outside the region
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 1, 2};
  const auto vb = rig.buffer("big vertices", verts.data(), verts.size() * sizeof(Vertex));
  const auto ib = rig.buffer("big indices", idx.data(), idx.size() * 4);
  auto levels = rig.run([&] { rig.vox->add_mesh(*rig.graph, "big", vb, ib, {{0, 3, 0}, {3, 3, 3}}); });
  int holes = 0, stray = 0;
  for (uint32_t z = 0; z < kN; ++z)
    for (uint32_t y = 0; y < kN; ++y)
      for (uint32_t x = 0; x < kN; ++x) {
        const float occ = levels[0][at(x, y, z)].w;
        if (y == 8) holes += occ != 1.0f;
        else stray += occ != 0.0f;
      }
  EXPECT_EQ(holes, 0);
  EXPECT_EQ(stray, 0);
}

TEST_F(VulkanTest, VoxelizeDepthSurfaceJoinsNoPixelsAcrossADepthEdge) {
  Rig rig(ctx());
  // A 16 x 16 G-buffer: the left half a floor at y 0.35 (row 3) 1 m from the camera, the right
  // half a shelf at y 0.95 (row 9) 2 m away: a depth edge between them, no surface across it.
  constexpr uint32_t kW = 16;
  std::vector<float> pos;
  std::vector<uint16_t> nor;
  for (uint32_t v = 0; v < kW; ++v)
    for (uint32_t u = 0; u < kW; ++u) {
      const bool near = u < kW / 2;
      const float x = 0.05f + 0.1f * float(u), z = 0.05f + 0.1f * float(v);
      pos.insert(pos.end(), {x, near ? 0.35f : 0.95f, z, near ? 1.0f : 2.0f});
      for (float c : {0.0f, 1.0f, 0.0f, 0.0f}) nor.push_back(uint16_t(glm::packHalf1x16(c)));
    }
  auto image = [&](const char* name, VkFormat f) {
    gpu::ImageDesc d;
    d.name = name;
    d.format = f;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = kW;
    d.height = kW;
    return *rig.graph->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  };
  const auto position = image("positions", VK_FORMAT_R32G32B32A32_SFLOAT);
  const auto normal = image("normals", VK_FORMAT_R16G16B16A16_SFLOAT);
  ASSERT_TRUE(rig.graph->upload_image(position, pos.data(), pos.size() * 4).ok());
  ASSERT_TRUE(rig.graph->upload_image(normal, nor.data(), nor.size() * 2).ok());
  auto levels = rig.run([&] { rig.vox->add_depth_surface(*rig.graph, "real", position, normal, kW, kW); });
  int floor = 0, shelf = 0, between = 0;
  for (uint32_t z = 0; z < kN; ++z)
    for (uint32_t y = 0; y < kN; ++y)
      for (uint32_t x = 0; x < kN; ++x) {
        const glm::vec4 v = levels[0][at(x, y, z)];
        if (v.w == 0.0f) continue;
        EXPECT_NEAR(v.y, 1.0f, 1e-3f) << "normal of voxel " << x << " " << y << " " << z;
        if (y == 3) ++floor;
        else if (y == 9) ++shelf;
        else ++between;
      }
  EXPECT_EQ(floor, 8 * 16);  // pixel centres 0.05..0.75 in x: voxels 0..7, all 16 rows in z
  EXPECT_EQ(shelf, 8 * 16);
  EXPECT_EQ(between, 0) << "a triangle was made across the depth edge";
}

TEST_F(VulkanTest, VoxelizeRefusesSizesOutsideItsRange) {
  Rig rig(ctx());
  gi::VoxelizeSettings s;
  s.resolution = 512;
  auto bad = gi::Voxelizer::create(*rig.graph, s);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("VoxelizeSettings.resolution"), std::string::npos);
  EXPECT_FALSE(rig.vox->set_cells(*rig.graph, 5).ok());
  EXPECT_TRUE(rig.vox->set_cells(*rig.graph, 8).ok());
  EXPECT_EQ(rig.vox->cells(), 8u);
}

}  // namespace
