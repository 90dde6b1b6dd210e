// Surface voxelisation into a visibility volume, a shared block of the voxel techniques (dvct:
// Delta Voxel Cone Tracing, delta-voxel-cone-tracing.md Sec. 3.2): each voxel holds the mean
// normal of the surfaces in it and an occlusion, 1 where there is geometry and 0 elsewhere;
// the mip chain's mean makes a coarser voxel's occlusion the fraction of its sub-voxels holding
// geometry (Fig. 1 a), and its normal the mean of theirs (premultiplied by the occupancy, as
// shaders/shared/vct_math.h vct_directional_occlusion reads it).
//
// Per frame it is rebuilt: add_clear(), any number of add_mesh() (virtual objects, real proxy
// meshes) and add_depth_surface() (the reconstruction's G-buffer as a grid mesh), then
// add_resolve() (the finest level and the mip chain). The sampling voxeliser is in
// shaders/gi/voxelize_splat.glsl (why sampling, and its limits). Everything is allocated at
// create() for `resolution`; set_cells() picks the used size of a cheaper level.
#pragma once
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/volume.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gi {

struct VoxelizeSettings {
  std::string name = "voxels";  // prefix of its images, buffer and passes
  uint32_t resolution = 64;     // cells per side allocated (the largest level), 2..256
};

// Where the volume is this frame: its min corner and voxel size, metres (an axis-aligned cube of
// cells() voxels a side).
struct VoxelRegion {
  glm::vec3 origin{0.0f};
  float voxel_size = 0.01f;
};

// The region of Sec. 3.4: "the double sized bounding box of the virtual object", as a cube (the
// volumes are cubes of cells() voxels) around the box's centre whose side is twice the box's
// longest side, never under `min_side` metres (a flat or tiny object still gets a region its
// neighbourhood fits in).
inline VoxelRegion doubled_box_region(glm::vec3 box_min, glm::vec3 box_max, uint32_t cells, float min_side) {
  const glm::vec3 extent = glm::max(box_max - box_min, glm::vec3(0.0f));
  const float side = std::max(2.0f * std::max(extent.x, std::max(extent.y, extent.z)), min_side);
  const glm::vec3 centre = 0.5f * (box_min + box_max);
  return {centre - glm::vec3(0.5f * side), side / float(std::max(cells, 1u))};
}

// One indexed triangle range of a mesh whose vertices are frame/scene_gpu.h frame::GpuVertex (world
// position, normal, uv: 8 floats) in a storage buffer, with 32-bit indices.
struct TriangleRange {
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t vertex_offset = 0;
};

class Voxelizer {
 public:
  // BadUsage naming the field for settings out of range; Device when the device has no float
  // atomics on images (VK_EXT_shader_atomic_float shaderImageFloat32AtomicAdd).
  static Expected<Voxelizer> create(gpu::FrameGraph& graph, const VoxelizeSettings& settings);

  // Cells per side used from now on: resolution / k for an integer k, at least 2.
  Status set_cells(gpu::FrameGraph& graph, uint32_t cells);
  uint32_t cells() const { return volume_->cells(); }
  void set_region(const VoxelRegion& region) { region_ = region; }
  const VoxelRegion& region() const { return region_; }

  void add_clear(gpu::FrameGraph& graph);
  // The triangles of `ranges` (one pass, "<name> voxelize <label>"). The buffers must have
  // storage usage (the scene's meshes do).
  void add_mesh(gpu::FrameGraph& graph, const std::string& label, gpu::BufferHandle vertices,
                gpu::BufferHandle indices, const std::vector<TriangleRange>& ranges) const;
  // The real scene as the G-buffer holds it: `position` RGBA32F (xyz world, w depth, 0 invalid),
  // `normal` RGBA16F, `width` x `height` used pixels.
  // `stride`: G-buffer pixels between grid points (1: every pixel). The splat samples every
  // triangle at half a voxel whatever its size, so a stride only drops grid points a voxel does
  // not resolve (and depth edges finer than it).
  void add_depth_surface(gpu::FrameGraph& graph, const std::string& label, gpu::ImageHandle position,
                         gpu::ImageHandle normal, uint32_t width, uint32_t height, uint32_t stride = 1) const;
  // The finest level from the sums, then the mip chain.
  void add_resolve(gpu::FrameGraph& graph);
  // RGBA16F, every mip level: xyz the mean normal x occupancy, w the occlusion.
  const VoxelVolume& volume() const { return *volume_; }

 private:
  Voxelizer() = default;
  VoxelizeSettings settings_;
  VoxelRegion region_;
  std::optional<VoxelVolume> volume_;
  gpu::BufferHandle sums_;  // 4 floats a cell: normal x area (xyz), area (voxel^2)
  gpu::PipelineHandle mesh_, depth_, resolve_;
};

}  // namespace mrgi::gi
