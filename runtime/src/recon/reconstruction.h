// Reconstruction v0 (DESIGN.md "One frame, as data"): the real G-buffer from one RGB-D frame.
//   upload          colour (sRGB8) and depth (u16) copied into this frame slot's upload buffers
//   recon_positions depth -> view space (depth intrinsics, depth_scale; 0 = invalid) -> world
//                   (frame pose); albedo from the camera colour (DIR approximation)
//   recon_normals   normals from neighbouring positions (DIR eq. in section 4.2) with a
//                   backward-difference fallback at holes and depth edges, facing the camera
// Output images (internal resolution = output x render scale): real_position (RGBA32F: xyz
// world, w depth in metres; all 0 = invalid), real_normal (RGBA16F: xyz, w 1 valid),
// real_albedo (RGBA16F: linear rgb, w 1 valid). Invalid stays invalid in every later step.
// No temporal filtering yet (the DIR paper's warp-and-merge is not in v0).
#pragma once
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/frame.h"

namespace mrgi::recon {

class Reconstruction {
 public:
  // Buffers sized for the colour and depth images; images allocated at the output size.
  static Expected<Reconstruction> create(gpu::Context& context, gpu::FrameGraph& graph,
                                         const Intrinsics& color, const Intrinsics& depth);
  // Copies the frame's images into the current slot's upload buffers (sizes checked by the
  // caller). Call between FrameGraph::begin_frame and submit.
  void upload(const gpu::FrameGraph& graph, const InputFrame& frame) const;
  // Adds recon_positions and recon_normals.
  void record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants);

  gpu::BufferHandle color_upload() const { return color_upload_; }
  gpu::BufferHandle depth_upload() const { return depth_upload_; }
  gpu::ImageHandle position() const { return position_; }
  gpu::ImageHandle normal() const { return normal_; }
  gpu::ImageHandle albedo() const { return albedo_; }

 private:
  gpu::BufferHandle color_upload_, depth_upload_, frame_constants_;
  gpu::ImageHandle position_, normal_, albedo_;
  gpu::PipelineHandle positions_pipeline_, normals_pipeline_;
  size_t color_bytes_ = 0, depth_bytes_ = 0;
};

}  // namespace mrgi::recon
