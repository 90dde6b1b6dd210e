// Voxel volumes, a shared block of the GI techniques (dlpv now; dvct and dir next): RGBA float 3D
// images allocated once for the largest level, a used size per level (one divisor), clearing and
// a mip chain. What a technique injects is its own pass; this block owns the images and the
// passes every volume technique needs.
#pragma once
#include <array>
#include <string>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gi {

struct VolumeSettings {
  std::string name = "volume";  // prefix of the images' names (debug names, errors, pass names)
  // Cells per side at the largest level, allocated at start-up (2..256). The paper sizes for
  // DLPV are 32 (Table 3's best) down to 8 (the reduced-volume fast path).
  uint32_t resolution = 32;
  // Images of the same size, 1..4 (DLPV: three, the 4 SH coefficients of R, G and B).
  uint32_t images = 1;
  // RGBA16F, or RGBA32F where values span more than half floats hold (light propagation: a lamp
  // of 1e6 would overflow 65504). Mip chains are RGBA16F only.
  VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  // A full mip chain down to one cell (cone tracing reads coarser levels for wider cones).
  bool mip_chain = false;
  // Contents kept between frames (gpu::ImageDesc::history): a frame that does not rewrite the
  // volume reads what the last one left (dlpv reuses its volumes when nothing moved).
  bool history = false;
};

class VoxelVolume {
 public:
  // BadUsage naming the field for settings out of range; Device errors from the allocation.
  static Expected<VoxelVolume> create(gpu::FrameGraph& graph, const VolumeSettings& settings);

  // The used size this frame: resolution / divisor cells per side (1..resolution/2 ... any
  // divisor that leaves at least 2 cells). Never reallocates.
  Status set_divisor(gpu::FrameGraph& graph, uint32_t divisor);
  uint32_t cells() const { return (settings_.resolution + divisor_ - 1) / divisor_; }
  // Mip levels holding data at the used size (1 without a chain).
  uint32_t used_levels() const;
  uint32_t allocated_levels() const { return levels_; }
  gpu::ImageHandle image(uint32_t i) const { return images_.at(i); }
  uint32_t image_count() const { return settings_.images; }
  const VolumeSettings& settings() const { return settings_; }

  // set_divisor for `cells` per side (the voxel blocks' unit): BadUsage naming `what` unless it
  // divides the allocated resolution and is at least 2.
  Status set_cells(gpu::FrameGraph& graph, uint32_t cells, const std::string& what);
  // A transfer pass setting every image, every level, to zero.
  void add_clear(gpu::FrameGraph& graph) const;
  // For a volume whose passes write only the used corner of each level (the voxel blocks'
  // resolve and mip chain): add_clear() whenever the used size changed since the last one (a
  // cone's trilinear read at the corner's edge reaches half a voxel past it, where a larger
  // level's, or a former runtime's, values would otherwise still be). keep_cleared_margin() in
  // the frame's first pass that writes the corner then declares that it reads the levels it writes
  // in part, so the graph does not cull the clear as overwritten.
  void add_clear_if_resized(gpu::FrameGraph& graph);
  void keep_cleared_margin(gpu::ShaderPassBuilder& b);
  // Passes building levels 1..used_levels()-1 of every image from level 0 (a no-op without a chain).
  void add_mip_chain(gpu::FrameGraph& graph) const;

 private:
  VoxelVolume() = default;
  VolumeSettings settings_;
  uint32_t levels_ = 1;
  uint32_t divisor_ = 1;
  uint32_t cleared_cells_ = 0;  // the used size the images were last cleared for (0: never)
  bool clear_pending_ = false;  // add_clear_if_resized cleared this frame, not yet kept
  std::array<gpu::ImageHandle, 4> images_{};
  gpu::PipelineHandle downsample_;
};

}  // namespace mrgi::gi
