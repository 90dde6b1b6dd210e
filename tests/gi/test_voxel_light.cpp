// Voxel light volumes (runtime/src/gi/voxel_light.h) on lavapipe with validation: a map's
// reflected flux lands in the voxel of its surface as radiance x coverage (flux / (pi s^2)), the
// mip chain averages it, and the delta pair of DVCT Sec. 3.2 (with the object minus without)
// cancels where the maps agree and goes negative where the object hides a real surface.
#include <glm/gtc/packing.hpp>

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "gi/voxel_light.h"
#include "volume_readback.h"
#include "vulkan/vk_test_util.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kN = 8;
constexpr float kVoxel = 0.1f;

struct Texel {
  glm::vec4 position;  // w 1 real, 2 virtual, 0 none
  glm::vec3 flux;
};

struct Rig {
  std::unique_ptr<gpu::FrameGraph> graph;
  std::optional<gi::VoxelLight> light;
  gpu::BufferHandle readback;

  explicit Rig(gpu::Context& ctx) {
    graph = test::make_block_graph(ctx);
    gi::VoxelLightSettings s;
    s.name = "test light";
    s.resolution = kN;
    auto v = gi::VoxelLight::create(*graph, s);
    EXPECT_TRUE(v.ok()) << v.error().message;
    light.emplace(std::move(*v));
    light->set_region({glm::vec3(0.0f), kVoxel});
    readback = test::make_volume_readback(*graph, kN);
  }

  gi::RsmImages map(const std::string& name, const std::vector<Texel>& texels) {
    const uint32_t w = uint32_t(texels.size());
    auto image = [&](const std::string& what) {
      gpu::ImageDesc d;
      d.name = name + " " + what;
      d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
      d.size_mode = gpu::SizeMode::Absolute;
      d.width = w;
      d.height = 1;
      return *graph->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    };
    gi::RsmImages r{image("position"), {}, image("flux"), w, 1};
    std::vector<float> pos, flux;
    for (const Texel& t : texels) {
      pos.insert(pos.end(), {t.position.x, t.position.y, t.position.z, t.position.w});
      flux.insert(flux.end(), {t.flux.x, t.flux.y, t.flux.z, 0.0f});
    }
    EXPECT_TRUE(graph->upload_image(r.position, pos.data(), pos.size() * 4).ok());
    EXPECT_TRUE(graph->upload_image(r.flux, flux.data(), flux.size() * 4).ok());
    return r;
  }

  // One frame; returns levels 0 and 1 (rgb).
  std::vector<std::vector<glm::vec3>> run(const std::function<void()>& add) {
    const auto levels = test::run_and_read_volume(*graph, light->volume().image(0), readback, kN, [&] {
      light->add_clear(*graph);
      add();
      light->add_resolve(*graph);
    });
    std::vector<std::vector<glm::vec3>> out(2);
    for (size_t l = 0; l < 2; ++l)
      for (const glm::vec4& v : levels[l]) out[l].push_back(glm::vec3(v));
    return out;
  }
};

size_t at(uint32_t x, uint32_t y, uint32_t z, uint32_t n = kN) { return (size_t(z) * n + y) * n + x; }

const float kToRadiance = 1.0f / (std::numbers::pi_v<float> * kVoxel * kVoxel);

TEST_F(VulkanTest, VoxelLightHoldsAMapsFluxAsRadianceInItsSurfacesVoxel) {
  Rig rig(ctx());
  // Two texels of one real surface in voxel (5, 3, 7), one W each per channel scale, and one
  // with no surface (w 0): radiance 2 (1, 2, 3) / (pi s^2) there, nothing elsewhere.
  const auto rsm = rig.map("rsm", {{{0.52f, 0.35f, 0.75f, 1.0f}, {1, 2, 3}},
                                   {{0.58f, 0.31f, 0.71f, 1.0f}, {1, 2, 3}},
                                   {{0.15f, 0.15f, 0.15f, 0.0f}, {9, 9, 9}}});
  auto v = rig.run([&] { rig.light->add_inject(*rig.graph, "lamp", rsm, 1.0f); });
  int wrong = 0;
  for (uint32_t z = 0; z < kN; ++z)
    for (uint32_t y = 0; y < kN; ++y)
      for (uint32_t x = 0; x < kN; ++x) {
        const glm::vec3 want = (x == 5 && y == 3 && z == 7) ? 2.0f * kToRadiance * glm::vec3(1, 2, 3) : glm::vec3(0.0f);
        for (int c = 0; c < 3; ++c) wrong += std::abs(v[0][at(x, y, z)][c] - want[c]) > 2e-3f * (1.0f + std::abs(want[c]));
      }
  EXPECT_EQ(wrong, 0);
  // Level 1: the mean of the 8 voxels under it.
  const glm::vec3 coarse = v[1][at(2, 1, 3, kN / 2)];
  EXPECT_NEAR(coarse.z, 2.0f * kToRadiance * 3.0f / 8.0f, 0.05f);
}

TEST_F(VulkanTest, VoxelLightDeltaPairCancelsWhereTheMapsAgreeAndIsNegativeWhereTheObjectHides) {
  Rig rig(ctx());
  // R^mu: two real floor texels. R^rho: the same first texel, the second hidden by a virtual
  // surface 0.3 m above it (w 2) that reflects (0.5, 0.5, 0.5).
  const glm::vec4 floor_a(0.15f, 0.05f, 0.15f, 1.0f), floor_b(0.45f, 0.05f, 0.45f, 1.0f);
  const glm::vec4 object(0.45f, 0.35f, 0.45f, 2.0f);
  const auto mu = rig.map("mu", {{floor_a, {1, 1, 1}}, {floor_b, {1, 1, 1}}});
  const auto rho = rig.map("rho", {{floor_a, {1, 1, 1}}, {object, {0.5f, 0.5f, 0.5f}}});
  auto v = rig.run([&] { rig.light->add_inject(*rig.graph, "delta", rho, 1.0f, &mu); });
  EXPECT_NEAR(v[0][at(1, 0, 1)].x, 0.0f, 1e-6f) << "a texel both maps hold cancels";
  EXPECT_NEAR(v[0][at(4, 0, 4)].x, -kToRadiance, 2e-3f * kToRadiance) << "the hidden floor: negative";
  EXPECT_NEAR(v[0][at(4, 3, 4)].x, 0.5f * kToRadiance, 2e-3f * kToRadiance) << "the object's own light";
  // The same maps one by one give the same volume (the pair is an optimisation, not new math).
  auto w = rig.run([&] {
    rig.light->add_inject(*rig.graph, "rho", rho, 1.0f);
    rig.light->add_inject(*rig.graph, "mu", mu, -1.0f);
  });
  for (size_t i = 0; i < v[0].size(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(v[0][i][c], w[0][i][c], 1e-3f * (1.0f + std::abs(w[0][i][c]))) << i;
}

}  // namespace
