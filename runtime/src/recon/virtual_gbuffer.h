// The virtual G-buffer: the scene's glTF objects rasterised from the colour camera (OpenCV
// intrinsics -> Vulkan projection with y down and depth 0..1, FrameConstants::world_to_clip) at
// the internal resolution, hidden where the real surface is in front (recon's positions, or the
// technique's own real geometry: frame::RealGeometry).
// Images: virtual_position (RGBA32F: xyz world, w 1 where a virtual object is seen = the
// real/virtual mask), virtual_normal (RGBA16F: xyz, w roughness), virtual_albedo (RGBA16F:
// linear base colour, w metallic), virtual_emission (RGBA16F: emitted radiance, glTF emissive),
// virtual_depth (D32, for the virtual objects among themselves).
// At an internal resolution other than the output's it also rasterises the objects' coverage at
// the output resolution (virtual_coverage, R32F: 1 where one is seen), with the same occlusion test by
// the real geometry (shaders/gbuffer/hidden_by_real.glsl), so the mask and the silhouettes the
// user sees come at the output's pixels whatever the internal scale (compose up-samples the
// lighting from the texels on the same side of it).
#pragma once
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "frame/scene_gpu.h"
#include "frame/frame_resources.h"
#include "common/frame_constants.glsl"

namespace mrgi::recon {

class VirtualGBuffer {
 public:
  static Expected<VirtualGBuffer> create(gpu::Context& context, gpu::FrameGraph& graph,
                                         const frame::SceneGpu& scene);
  // Adds the pass "virtual_gbuffer" (always: with no object it clears the mask) and, when the
  // internal resolution differs from the output's, "virtual_coverage".
  // Mesh ranges are drawn at the coarsest level of detail within `mesh_error_px` projected
  // internal pixels (QualityLevel::mesh_error_px; 0 = full detail).
  void record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants,
              const frame::RealGeometry& real, float mesh_error_px);

  gpu::ImageHandle position() const { return position_; }
  gpu::ImageHandle normal() const { return normal_; }
  gpu::ImageHandle albedo() const { return albedo_; }
  // Invalid when no virtual material emits (the target is then not allocated or drawn).
  gpu::ImageHandle emission() const { return emission_; }
  // This frame's coverage at the output resolution; invalid when the G-buffer has the output's
  // size (position()'s w is then the mask at the output's pixels).
  gpu::ImageHandle output_coverage() const { return coverage_recorded_ ? coverage_ : gpu::ImageHandle{}; }
  // The internal pixels where this frame's virtual pixels can be: the visible objects' projected
  // bounds with a pixel of margin (the whole image when a bound's corner is behind the camera),
  // empty without an object. Valid after record(); outside it every pixel is real.
  VkRect2D objects_area() const { return area_.previous; }
  // The output pixels this frame's coverage raster drew and cleared; outside it the coverage is
  // 0 (empty without a coverage raster).
  VkRect2D output_coverage_area() const {
    return coverage_recorded_ ? coverage_area_.now : VkRect2D{{0, 0}, {0, 0}};
  }

 private:
  // The area a raster draws and clears this frame: the virtual objects' projected bounds united
  // with the previous frame's (so what that frame drew is cleared), the whole image on the first
  // frame, after a size change or when a bound's corner is behind the camera. Outside it every
  // texel is still the clear value, so readers see an empty target there as before. Why: the
  // four full-screen clears cost 1.4 ms of the G-buffer pass on lavapipe at 640x480.
  struct RasterArea {
    // now: the area drawn and cleared; previous: after update_area, this frame's objects' bounds
    // (what the next frame must clear).
    VkRect2D now{{0, 0}, {0, 0}}, previous{{0, 0}, {0, 0}};
    VkExtent2D previous_extent{0, 0};
  };
  void draw(VkCommandBuffer cmd, gpu::PassContext& pass);
  void draw_coverage(VkCommandBuffer cmd, gpu::PassContext& pass);
  void record_coverage(gpu::FrameGraph& graph);
  void bind_raster_inputs(gpu::ShaderPassBuilder& b, VkSampler nearest) const;
  // Sets `a.now` for a raster of `extent` from this frame's constants; updates its history.
  void update_area(RasterArea& a, VkExtent2D extent, const shader::FrameConstants& fc) const;

  const frame::SceneGpu* scene_ = nullptr;
  gpu::BufferHandle frame_constants_;
  frame::RealGeometry real_;
  // Why levels of detail: lavapipe sets triangles up on one thread (desk_spot's 16k-triangle
  // bunny, a few pixels per triangle at 640x480, cost 8.5 ms of this pass's 10; a quarter of
  // the triangles 1.7 ms).
  frame::LodView lod_;
  // The output coverage's own level of detail: within kCoverageMeshErrorPx output pixels (what
  // the silhouette needs; coarser than a full-detail G-buffer), or the G-buffer's where a
  // simplified G-buffer is finer than that. Why: lavapipe's triangle setup
  // made a full-detail coverage raster of desk_spot's bunny cost 4-6 ms.
  frame::LodView coverage_lod_;
  RasterArea area_, coverage_area_;  // the G-buffer's, the output coverage's
  gpu::ImageHandle position_, normal_, albedo_, emission_, depth_;
  gpu::ImageHandle coverage_;    // R32F at the output resolution
  bool coverage_recorded_ = false;  // this frame
  gpu::PipelineHandle pipeline_, double_sided_pipeline_;  // back faces culled; both sides
  gpu::PipelineHandle coverage_pipeline_, coverage_double_sided_pipeline_;
  VkImageLayout color_layout_ = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkImageLayout depth_layout_ = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
};

}  // namespace mrgi::recon
