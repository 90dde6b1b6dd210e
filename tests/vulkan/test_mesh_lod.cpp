// Levels of detail of the virtual meshes (frame/scene_gpu.h frame::DrawRange::lods): built once at
// start-up with meshoptimizer, chosen per draw by the projected error.
#include <gtest/gtest.h>

#include <filesystem>

#include "gpu/frame_graph.h"
#include "frame/scene_gpu.h"
#include "vk_test_util.h"

namespace mrgi::test {
namespace {

frame::DrawRange range_with_errors(std::initializer_list<float> errors) {
  frame::DrawRange r;
  r.bounds_min = glm::vec3(-0.1f, -0.1f, 1.9f);
  r.bounds_max = glm::vec3(0.1f, 0.1f, 2.1f);
  uint32_t count = 3000;
  for (float e : errors) {
    r.lods.push_back({0, count, e});
    count /= 2;
  }
  return r;
}

TEST(MeshLod, TheCoarsestLevelWithinTheProjectedErrorIsChosen) {
  // Nearest point of the bounds 1.9 m from the camera, 500 px focal: 1 mm = 0.26 px.
  const frame::DrawRange r = range_with_errors({0.0f, 0.001f, 0.0019f, 0.0037f});
  frame::LodView view;
  view.camera_world = glm::vec3(0.0f);
  view.focal_px = 500.0f;
  view.max_error_px = 0.5f;
  EXPECT_EQ(frame::MeshSet::select_lod(r, view), 2u);  // 0.0019 m -> 0.5 px, 0.0037 -> 0.97
  view.focal_px = 250.0f;  // half the resolution: 0.0037 m -> 0.49 px
  EXPECT_EQ(frame::MeshSet::select_lod(r, view), 3u);
  view.focal_px = 2000.0f;
  EXPECT_EQ(frame::MeshSet::select_lod(r, view), 0u);  // 1 mm is 1.05 px
  // The camera inside the bounds: no level but the original.
  view.camera_world = glm::vec3(0.0f, 0.0f, 2.0f);
  view.focal_px = 1.0f;
  EXPECT_EQ(frame::MeshSet::select_lod(r, view), 0u);
  // Full detail asked for (max_error_px 0), and no levels (proxies): 0.
  view.camera_world = glm::vec3(0.0f);
  view.focal_px = 500.0f;
  view.max_error_px = 0.0f;
  EXPECT_EQ(frame::MeshSet::select_lod(r, view), 0u);
  EXPECT_EQ(frame::MeshSet::select_lod(frame::DrawRange{}, view), 0u);
}

TEST_F(VulkanTest, AVirtualMeshGetsCoarserLevelsOfItsOwnVertices) {
  const std::filesystem::path bunny =
      std::filesystem::path(MRGI_SOURCE_DIR) / "perf/suite/desk_spot/virtual/0_bunny.glb";
  ASSERT_TRUE(std::filesystem::exists(bunny)) << bunny;
  gpu::FrameGraphSettings fs;
  fs.max_output_width = 64;
  fs.max_output_height = 48;
  auto graph = gpu::FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(graph.ok()) << graph.error().message;
  SceneDesc scene;
  scene.virtual_objects.push_back({bunny.string(), {}});
  auto sg = frame::SceneGpu::create(ctx(), **graph, scene);
  ASSERT_TRUE(sg.ok()) << sg.error().message;
  const auto& draws = (*sg)->virtual_objects.draws;
  ASSERT_EQ(draws.size(), 1u);
  const frame::DrawRange& d = draws[0];
  ASSERT_GE(d.lods.size(), 3u) << "16k triangles simplify at least twice";
  EXPECT_EQ(d.lods[0].first_index, d.first_index);
  EXPECT_EQ(d.lods[0].index_count, d.index_count);
  EXPECT_EQ(d.lods[0].error_m, 0.0f);
  for (size_t i = 1; i < d.lods.size(); ++i) {
    EXPECT_EQ(d.lods[i].index_count % 3, 0u);
    EXPECT_LE(d.lods[i].index_count, d.lods[i - 1].index_count * 8 / 10) << "level " << i;
    EXPECT_GE(d.lods[i].error_m, d.lods[i - 1].error_m) << "level " << i;
    EXPECT_GT(d.lods[i].error_m, 0.0f);
    // Bounded by kMaxLodRelativeError (5 %) of the mesh's extent.
    const float extent = glm::length(d.bounds_max - d.bounds_min);
    EXPECT_LT(d.lods[i].error_m, 0.05f * extent) << "level " << i;
    EXPECT_GE(d.lods[i].first_index, d.first_index + d.index_count) << "after the original";
  }
  // A far camera picks a coarse level, a near one the original.
  frame::LodView view;
  view.focal_px = 525.0f;
  const glm::vec3 centre = 0.5f * (d.bounds_min + d.bounds_max);
  view.camera_world = centre + glm::vec3(0.0f, 0.0f, 50.0f);
  EXPECT_EQ(frame::MeshSet::select_lod(d, view), d.lods.size() - 1);
  view.camera_world = centre + glm::vec3(0.0f, 0.0f, 0.3f);
  view.focal_px = 5000.0f;
  EXPECT_EQ(frame::MeshSet::select_lod(d, view), 0u);
}

}  // namespace
}  // namespace mrgi::test
