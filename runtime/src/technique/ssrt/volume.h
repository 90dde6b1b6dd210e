// The ssrt technique's volume V (paper Sec. 4 and 5.1): a KinectFusion TSDF of the workspace
// (Newcombe et al. 2011, the paper's ref. [21]; "2x2x2 m workspace reconstructed into a 256^3
// voxel volume", 64^3 on mobile), its ray-cast view G_v (D_v + N_v) at the internal resolution,
// and the four auxiliary orthographic geometry buffers (left, right, top of the camera, and the
// dominant light's view) that give the radiance transfer occluders outside the camera frustum.
//
// Passes (in order; all allocated at create() for the top level, nothing per frame):
//   ssrt_tsdf_clear    transfer: zeroes the level's voxels on a reset (first frame, resolution or
//                      centre change); only on those frames
//   ssrt_tsdf_fuse     projective TSDF update from this frame's raw depth (depth_upload)
//   ssrt_tsdf_raycast  D_v (R32F, camera z m, 0 = none) and N_v (RGBA16F world normal, w valid)
//   ssrt_tsdf_aux      the 4 layers of aux_position() (views and occlusion rule: aux_views.glsl)
// Skips (each appended to `skipped` as "pass: reason"):
//   - fuse: the pose moved less than both pose tolerances since the last fused frame AND the
//     depth is unchanged (mean |dz| over pixels valid in both below depth_tolerance_m, valid
//     counts within 1 %); a frame without a host depth copy is always fused.
//   - raycast and aux: when the fuse was skipped and nothing else they depend on changed since
//     they last ran (resolution, aux resolution, centre, light direction, internal size and
//     intrinsics): their images are persistent and keep that frame's result, which is then the
//     view from a pose within the pose tolerances of the current one. When the fuse is skipped
//     but something else changed, they run.
// Inputs: the depth comes from shared.depth_upload (this slot's copy, written by recon before
// these passes) with shared.depth_intrinsics / depth_scale; the view's intrinsics and size are
// the frame constants' internal_k / internal_output_size; VolumeFrame::camera_to_world must be
// the frame constants' pose (the passes use it in double-precision-derived form).
// Measured on lavapipe (LP_NUM_THREADS=2, 640x480 view, 256^2 aux texels): 256^3 fuse ~140 ms,
// raycast ~430 ms, aux ~300 ms; 64^3 fuse ~5 ms, raycast ~160-240 ms, aux ~80-130 ms.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "frame/camera_view.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "mrgi/image.h"
#include "ssrt/aux_views.glsl"
#include "technique/technique.h"

namespace mrgi::ssrt {

struct VolumeSettings {            // units in names, defaults = paper
  uint32_t max_resolution = 256;   // voxels per side allocated at start-up (the top level's)
  float size_m = 2.0f;             // cube side (paper: 2 m workspace)
  float truncation_voxels = 4.0f;  // TSDF truncation mu, in voxels of the current resolution
  float max_weight = 64.0f;        // running-average cap, frames
  uint32_t max_aux_resolution = 256; // texels per side of each auxiliary buffer
  // Re-fusion skip: no fuse pass when the pose moved less than both pose tolerances since the
  // last fused frame AND the depth image is unchanged (host-side: mean |dz| over pixels valid in
  // both below depth_tolerance_m, and the valid-pixel count within 1 %).
  double pose_tolerance_m = 0.001, pose_tolerance_deg = 0.1, depth_tolerance_m = 0.002;
};

struct VolumeFrame {
  uint32_t resolution = 256;       // this level's voxels per side (<= max); a change resets V
  uint32_t aux_resolution = 256;   // this level's aux texels per side (<= max)
  glm::vec3 center{0.0f};          // world centre of the cube; a change resets V
  glm::dmat4 camera_to_world{1.0}; // this frame's pose (the frame constants' pose)
  // The host's view of the depth (frame/camera_view.h; for frames given as the app's images an
  // earlier frame's), for the skip test; null: always fused.
  const frame::DepthView* depth = nullptr;
  glm::vec3 direction_to_light{0, 1, 0}; // unit, towards the dominant light (light aux buffer)
};

class Volume {
 public:
  static Expected<Volume> create(gpu::Context& ctx, gpu::FrameGraph& graph,
                                 const frame::FrameResources& shared,
                                 const VolumeSettings& s = {});
  // Adds ssrt_tsdf_clear (resets only), ssrt_tsdf_fuse, ssrt_tsdf_raycast, ssrt_tsdf_normals
  // (the graph culls it unless normal_volume() is read), ssrt_tsdf_aux, or
  // appends "<pass>: <reason>" to `skipped` for each left out. Errors (BadUsage) name the field.
  Status record(const VolumeFrame& frame, std::vector<std::string>& skipped);
  gpu::ImageHandle depth_volume() const { return depth_volume_; }    // R32F: D_v, camera z m, 0 none
  gpu::ImageHandle normal_volume() const { return normal_volume_; }  // RGBA16F: N_v, w 1 valid / 0
  // RGBA32F, 4 layers (0 left, 1 right, 2 top, 3 light): xyz world position of the first
  // surface, w its depth along the view axis in metres (0 = no surface).
  gpu::ImageHandle aux_position() const { return aux_position_; }
  gpu::BufferHandle aux_views() const { return aux_views_; }        // uniform: shader::SsrtAuxViews
  gpu::BufferHandle voxels() const { return voxels_; }              // storage: tsdf_volume.glsl
  bool fused_last_frame() const { return fused_last_frame_; }
  const VolumeSettings& settings() const { return settings_; }

 private:
  Volume() = default;
  Status validate(const VolumeFrame& frame) const;
  // The skip test against the last fused frame (host side).
  bool unchanged_since_last_fuse(const VolumeFrame& frame) const;
  void write_params(const VolumeFrame& frame);
  shader::SsrtAuxViews make_views(const VolumeFrame& frame) const;
  void add_passes(const VolumeFrame& frame, bool clear, bool fuse, bool views);

  VolumeSettings settings_;
  frame::FrameResources shared_;
  gpu::FrameGraph* graph_ = nullptr;
  gpu::BufferHandle voxels_, params_, aux_views_;
  gpu::ImageHandle depth_volume_, normal_volume_, aux_position_;
  gpu::PipelineHandle fuse_, raycast_, normals_, aux_;
  // Host state of the skip tests (allocated at create).
  ImageU16 last_depth_;
  bool has_fused_ = false, last_depth_valid_ = false, fused_last_frame_ = false;
  bool views_valid_ = false;
  shader::SsrtAuxViews views_{};   // of the aux layers as last ray-cast
  glm::dmat4 last_fused_pose_{1.0};
  uint32_t resolution_ = 0;        // of the voxels' contents; 0 = never cleared
  glm::vec3 center_{0.0f};
  // What the last ray-cast views depended on besides the volume.
  struct ViewKey {
    uint32_t aux_resolution = 0;
    glm::vec3 direction_to_light{0.0f};
    glm::vec4 internal_k{0.0f};
    glm::ivec2 internal_size{0};
    bool operator==(const ViewKey&) const = default;
  } view_key_;
};

}  // namespace mrgi::ssrt
