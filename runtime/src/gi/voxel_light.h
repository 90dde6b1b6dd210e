// Voxel light volumes, a shared block of the voxel techniques (dvct, delta-voxel-cone-tracing.md
// Sec. 3.2): the light the surfaces of a region send, injected from reflective shadow maps
// (gi/rsm.h) as radiance premultiplied by coverage (shaders/gi/voxel_inject.comp says why that
// quantity), with a mip chain for cone tracing. The paper's two light volumes are two of these:
// the light volume (the map with the virtual objects, +1) for shading virtual pixels, and the
// delta light volume (the pair: with the objects +1, without -1) for relighting real ones.
//
// Per frame: add_clear(), add_inject() for each lamp's map or pair, add_resolve(). Allocated at
// create() for `resolution`; set_cells() picks a cheaper level's size; the region is the
// visibility volumes' (gi/voxelize.h VoxelRegion), so a cone reads light and occlusion of the
// same voxel.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gi/light_propagation.h"
#include "gi/volume.h"
#include "gi/voxelize.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gi {

struct VoxelLightSettings {
  std::string name = "voxel light";
  uint32_t resolution = 64;  // cells per side allocated, 2..256
  bool surfaces = false;     // add_inject_surfaces is used (its pipeline is created)
};

// What add_inject_surfaces lights: the virtual objects' mesh set (frame/scene_gpu.h), its
// materials and base-colour maps, and the light set whose ambient lights it.
struct SurfaceLightSource {
  gpu::BufferHandle vertices, indices, materials;  // GpuVertex[], uint32 indices, GpuMaterial[]
  gpu::ImageHandle base_color_maps;
  gpu::BufferHandle light_set;  // shader::LightSet (uniform), its ambient_rv
  struct Range {
    uint32_t first_index = 0, index_count = 0;
    int32_t vertex_offset = 0, material = 0;
  };
  std::vector<Range> ranges;
  bool emission = false;  // add the materials' emission (some material emits)
};

class VoxelLight {
 public:
  // BadUsage naming the field; Device without float atomics on images.
  static Expected<VoxelLight> create(gpu::FrameGraph& graph, const VoxelLightSettings& settings);

  Status set_cells(gpu::FrameGraph& graph, uint32_t cells);
  uint32_t cells() const { return volume_->cells(); }
  void set_region(const VoxelRegion& region) { region_ = region; }
  const VoxelRegion& region() const { return region_; }

  void add_clear(gpu::FrameGraph& graph);
  // `rsm`'s texels with `sign`; with `other`, the pair: `rsm` with sign and `other` with -sign
  // where the two differ (voxel_inject.comp). One pass, "<name> inject <label>".
  void add_inject(gpu::FrameGraph& graph, const std::string& label, const RsmImages& rsm, float sign,
                  const RsmImages* other = nullptr) const;
  // The virtual surfaces' own light (voxel_inject_surfaces.comp): the ambient's irradiance on
  // each surface x its diffuse albedo, plus its emission, over the area it has in each voxel.
  // One pass, "<name> inject <label>". Needs settings.surfaces. The pass reads `source` when
  // it is recorded and run: it must outlive the frame's submission (its owner keeps it, made
  // once at start-up, so nothing is copied per frame).
  void add_inject_surfaces(gpu::FrameGraph& graph, const std::string& label, const SurfaceLightSource& source) const;
  void add_resolve(gpu::FrameGraph& graph);
  // RGBA16F, every mip level: rgb radiance x coverage (W / (sr m^2)), a unused.
  const VoxelVolume& volume() const { return *volume_; }

 private:
  VoxelLight() = default;
  VoxelLightSettings settings_;
  VoxelRegion region_;
  std::optional<VoxelVolume> volume_;
  gpu::BufferHandle sums_;  // 3 floats a cell: flux rgb (W)
  gpu::PipelineHandle inject_[2], resolve_;  // inject_[1]: the delta pair
  gpu::PipelineHandle surfaces_;             // settings.surfaces only
};

}  // namespace mrgi::gi
