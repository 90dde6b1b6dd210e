// Imperfect shadow maps (Ritschel et al. 2008), a shared block of the VPL-based techniques (dir
// now): for every VPL of a gi/vpl.h buffer, two paraboloid maps of the distance to the nearest
// surface over its hemisphere (shared/vpl_math.h), one from the real scene's points and one from
// the virtual objects' (the DIR paper's two ISMs per VPL, Sec. 3.3), made from sparse point
// clouds splatted in compute (the reconstruction's G-buffer at Halton positions; the virtual
// meshes' triangles at Halton barycentrics), and holes filled by a two-level pull-push.
//
// Layout: square tiles of `map_size` texels, one per VPL, `tiles_per_row` a row
// (ceil(sqrt(VPLs))), in two R32UI splat atlases and one RG32F distance atlas (x real, y
// virtual; MRGI_ISM_NONE where no surface is) with two pull-push levels; shaders look them up
// with gi/ism_common.glsl. Allocated once for the largest VPL count and map size.
#pragma once
#include <cstdint>
#include <string>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "frame/scene_gpu.h"

namespace mrgi::gi {

struct IsmSettings {
  std::string name = "ism";
  uint32_t max_vpls = 256;  // VPL slots (the VPL buffer's), 1..4096
  uint32_t map_size = 128;  // texels per side of one VPL's map, a power of two, 8..512
  // The maps keep their contents between frames (gpu::ImageDesc::history): a frame that does not
  // build them reads what the last one left (dir reuses its ISMs while nothing moved).
  bool history = false;
};

// What one frame's maps are made of.
struct IsmFrame {
  uint32_t vpls = 0;              // slots [0, vpls) of the VPL buffer (empty slots splat nothing)
  uint32_t map_size = 0;          // texels per side (power of two <= the allocated size)
  uint32_t points_per_vpl = 0;    // per atlas: each VPL's map gets this many real and virtual points
  glm::vec2 focal_px{0.0f};       // the real G-buffer's focal lengths (fx, fy) in its pixels
};

class ImperfectShadowMaps {
 public:
  // `real_position`, `real_normal`: the real G-buffer (xyz world, w depth, 0 none; unit normal).
  // BadUsage naming the field for settings out of range.
  static Expected<ImperfectShadowMaps> create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                              gpu::ImageHandle real_position, gpu::ImageHandle real_normal,
                                              const IsmSettings& settings);
  // Passes "<name> clear", "<name> splat real", "<name> splat virtual" (with virtual objects),
  // "<name> pull 1", "<name> pull 2", "<name> push 1", "<name> resolve".
  Status add_build(gpu::FrameGraph& graph, gpu::BufferHandle vpls, const IsmFrame& frame);

  gpu::ImageHandle distances() const { return distances_; }  // RG32F, level 0 the maps
  uint32_t tiles_per_row(uint32_t vpls) const;
  const IsmSettings& settings() const { return settings_; }

 private:
  ImperfectShadowMaps() = default;
  IsmSettings settings_;
  const frame::SceneGpu* scene_ = nullptr;
  gpu::ImageHandle real_position_, real_normal_;
  gpu::ImageHandle splat_real_, splat_virtual_, distances_;
  gpu::PipelineHandle clear_, splat_real_pipe_, splat_virtual_pipe_, pull_splat_, pull_, push_, resolve_;
};

}  // namespace mrgi::gi
