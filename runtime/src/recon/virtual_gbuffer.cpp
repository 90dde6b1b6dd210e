#include "recon/virtual_gbuffer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "common/frame_constants.glsl"
#include "gpu/shaders.h"

namespace mrgi::recon {
namespace {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kAlbedoFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kEmissionFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
// R32F: a storage format every Vulkan device supports (R8's storage use is optional).
constexpr VkFormat kCoverageFormat = VK_FORMAT_R32_SFLOAT;
// The output coverage's largest projected mesh error, output pixels: half a pixel moves a
// silhouette across at most one pixel centre.
constexpr float kCoverageMeshErrorPx = 0.5f;

// virtual_vertex.glsl's push constant after the material index (which SceneGpu::draw pushes per
// draw at offset 0): texels of the real geometry per raster pixel (x, y), at offset 8.
constexpr uint32_t kRealScaleOffset = 8;

// internal: at the internal resolution (follows the render scale), else at the output's.
Expected<gpu::ImageHandle> gbuffer_image(gpu::FrameGraph& graph, const char* name, VkFormat format,
                                          VkImageUsageFlags usage, bool internal = true) {
  gpu::ImageDesc d;
  d.name = name;
  d.format = format;
  d.size_mode = gpu::SizeMode::OutputRelative;
  d.follows_render_scale = internal;
  return graph.create_image(d, usage);
}

// The raster's two pipelines: back faces culled (single-sided materials), and both sides.
Status culled_and_double_sided(gpu::Context& context, gpu::GraphicsPipelineDesc desc, const std::string& name,
                               gpu::PipelineHandle& culled, gpu::PipelineHandle& both) {
  desc.name = name;
  desc.cull_mode = VK_CULL_MODE_BACK_BIT;
  auto one = gpu::create_graphics_pipeline(context, desc);
  if (!one) return one.error();
  culled = gpu::PipelineHandle(context, std::move(*one));
  desc.name = name + "_double_sided";
  desc.cull_mode = VK_CULL_MODE_NONE;
  auto two = gpu::create_graphics_pipeline(context, desc);
  if (!two) return two.error();
  both = gpu::PipelineHandle(context, std::move(*two));
  return ok_status();
}

// The viewport over the whole raster of size e; the scissor on the area drawn this frame.
void set_viewport(VkCommandBuffer cmd, VkExtent2D e, const VkRect2D& area) {
  const VkViewport vp{0.0f, 0.0f, float(e.width), float(e.height), 0.0f, 1.0f};
  vkCmdSetViewport(cmd, 0, 1, &vp);
  vkCmdSetScissor(cmd, 0, 1, &area);
}

VkRenderingAttachmentInfo cleared_color(VkImageView view, VkImageLayout layout) {
  VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  a.imageView = view;
  a.imageLayout = layout;
  a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  a.clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  return a;
}

}  // namespace

Expected<VirtualGBuffer> VirtualGBuffer::create(gpu::Context& context, gpu::FrameGraph& graph,
                                                const frame::SceneGpu& scene) {
  VirtualGBuffer v;
  v.scene_ = &scene;
  // Storage: compute passes read it with imageLoad (on lavapipe 2-3x cheaper than a sampled
  // texelFetch).
  const VkImageUsageFlags color =
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  auto p = gbuffer_image(graph, "virtual_position", kPositionFormat, color);
  if (!p) return p.error();
  v.position_ = *p;
  auto n = gbuffer_image(graph, "virtual_normal", kNormalFormat, color);
  if (!n) return n.error();
  v.normal_ = *n;
  auto a = gbuffer_image(graph, "virtual_albedo", kAlbedoFormat, color);
  if (!a) return a.error();
  v.albedo_ = *a;
  // The emission target only where some material emits: a fourth target cost the pass about
  // 1 ms of its 5 on lavapipe (desk_spot), for a scene whose objects emit nothing.
  if (scene.emissive) {
    auto em = gbuffer_image(graph, "virtual_emission", kEmissionFormat, color);
    if (!em) return em.error();
    v.emission_ = *em;
  }
  auto d = gbuffer_image(graph, "virtual_depth", kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  if (!d) return d.error();
  v.depth_ = *d;
  auto c = gbuffer_image(graph, "virtual_coverage", kCoverageFormat, color, false);
  if (!c) return c.error();
  v.coverage_ = *c;
  v.color_layout_ =
      gpu::access_info(gpu::PassKind::Graphics, gpu::Access::ColorAttachmentWrite, true, false).layout;
  v.depth_layout_ =
      gpu::access_info(gpu::PassKind::Graphics, gpu::Access::DepthAttachmentWrite, true, true).layout;

  auto vs = gpu::shader_spirv("gbuffer/virtual.vert");
  if (!vs) return vs.error();
  auto fs = gpu::shader_spirv("gbuffer/virtual.frag");
  if (!fs) return fs.error();
  gpu::GraphicsPipelineDesc desc;
  desc.vertex_spirv = *vs;
  desc.fragment_spirv = *fs;
  // Bindings and push constants (material per draw, real geometry scale) from the shaders.
  desc.vertex_strides = {sizeof(frame::GpuVertex)};
  desc.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(frame::GpuVertex, position)},
                     {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(frame::GpuVertex, normal)},
                     {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(frame::GpuVertex, uv)}};
  desc.color_formats = {kPositionFormat, kNormalFormat, kAlbedoFormat};
  // Without the emission target the fragment shader's fourth output has no attachment: Vulkan
  // discards such a write.
  if (scene.emissive) desc.color_formats.push_back(kEmissionFormat);
  desc.depth_format = kDepthFormat;
  desc.depth_compare = VK_COMPARE_OP_LESS;
  // Single-sided materials (glTF's default) cull back faces; the loader keeps front faces
  // counter-clockwise in world space (mirroring transforms swap the winding), and the camera's
  // y-down projection keeps them counter-clockwise on screen in Vulkan's framebuffer
  // convention (checked: culling the other side makes desk_spot's bunny show its inside, RDE
  // 0.83 -> 0.98). Cost on lavapipe, desk_spot's 16k-triangle bunny: 7.7 -> 5.8 ms.
  desc.front_face = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  MRGI_TRY(culled_and_double_sided(context, desc, "virtual_gbuffer", v.pipeline_, v.double_sided_pipeline_));

  // The output coverage: the same vertices and culling, one R32F target, no depth (any object
  // covering a pixel covers it).
  auto cvs = gpu::shader_spirv("gbuffer/virtual_coverage.vert");
  if (!cvs) return cvs.error();
  auto cfs = gpu::shader_spirv("gbuffer/virtual_coverage.frag");
  if (!cfs) return cfs.error();
  desc.vertex_spirv = *cvs;
  desc.fragment_spirv = *cfs;
  desc.color_formats = {kCoverageFormat};
  desc.depth_format = VK_FORMAT_UNDEFINED;
  desc.depth_compare = VK_COMPARE_OP_ALWAYS;
  MRGI_TRY(culled_and_double_sided(context, desc, "virtual_coverage", v.coverage_pipeline_,
                                   v.coverage_double_sided_pipeline_));
  return v;
}

void VirtualGBuffer::record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants,
                            const frame::RealGeometry& real, float mesh_error_px) {
  frame_constants_ = frame_constants;
  real_ = real;
  // Level of detail from this frame's camera (the constants the runtime just wrote).
  shader::FrameConstants fc;
  std::memcpy(&fc, graph.mapped(frame_constants, graph.slot()), sizeof(fc));
  lod_.camera_world = glm::vec3(fc.camera_world);
  lod_.focal_px = fc.internal_k.x;
  lod_.max_error_px = mesh_error_px;
  update_area(area_, graph.extent(position_), fc);
  const VkSampler nearest = graph.context().samplers().nearest_clamp;
  const VkSampler linear = graph.context().samplers().linear_repeat;
  graph.add_shader_pass(
      "virtual_gbuffer", gpu::PassKind::Graphics, *pipeline_,
      [this, nearest, linear](gpu::ShaderPassBuilder& b) {
        bind_raster_inputs(b, nearest);
        b.bind("Materials", scene_->materials);
        b.bind_sampled("base_color_maps", scene_->base_color_maps, linear);
        gpu::PassBuilder& u = b.uses();
        u.write(position_, gpu::Access::ColorAttachmentWrite);
        u.write(normal_, gpu::Access::ColorAttachmentWrite);
        u.write(albedo_, gpu::Access::ColorAttachmentWrite);
        if (emission_.valid()) u.write(emission_, gpu::Access::ColorAttachmentWrite);
        u.write(depth_, gpu::Access::DepthAttachmentWrite);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) { draw(cmd, pass); });
  const VkExtent2D internal = graph.extent(position_), output = graph.extent(coverage_);
  coverage_recorded_ = internal.width != output.width || internal.height != output.height;
  if (!coverage_recorded_) {
    coverage_area_.previous_extent = {0, 0};  // the next coverage frame clears all of it
    return;
  }
  update_area(coverage_area_, output, fc);
  // Within kCoverageMeshErrorPx output pixels whatever the G-buffer's level of detail. Drawing
  // the coverage as finely as a simplified G-buffer (the same mesh in both) makes it 2-5 CPU-ms
  // dearer at baseline lowest's 0.2 internal pixels (0.4 output) for no change of the frames'
  // error (desk_spot, env_fisheye, glossy_table within 0.0002 RDE;
  // perf/results/direct-light-block/mesh-lod-lowest-2026-12-06.md): the silhouettes differ by
  // as much beside a full-detail G-buffer.
  coverage_lod_ = {lod_.camera_world, fc.output_k.x, kCoverageMeshErrorPx};
  record_coverage(graph);
}

// What both rasters read: the frame constants, the real geometry of the occlusion test, the
// virtual objects' vertices.
void VirtualGBuffer::bind_raster_inputs(gpu::ShaderPassBuilder& b, VkSampler nearest) const {
  b.bind("FrameUbo", frame_constants_);
  b.bind_sampled("real_position", real_.position, nearest);
  b.bind_sampled("real_normal", real_.normal, nearest);
  b.uses().read(scene_->virtual_objects.vertices, gpu::Access::VertexBuffer);
  b.uses().read(scene_->virtual_objects.indices, gpu::Access::IndexBuffer);
}

void VirtualGBuffer::record_coverage(gpu::FrameGraph& graph) {
  const VkSampler nearest = graph.context().samplers().nearest_clamp;
  graph.add_shader_pass(
      "virtual_coverage", gpu::PassKind::Graphics, *coverage_pipeline_,
      [this, nearest](gpu::ShaderPassBuilder& b) {
        bind_raster_inputs(b, nearest);
        b.uses().write(coverage_, gpu::Access::ColorAttachmentWrite);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) { draw_coverage(cmd, pass); });
}

void VirtualGBuffer::update_area(RasterArea& a, VkExtent2D e, const shader::FrameConstants& fc) const {
  const VkRect2D full{{0, 0}, e};
  const bool same_size = e.width == a.previous_extent.width && e.height == a.previous_extent.height;
  a.previous_extent = e;
  VkRect2D now{{0, 0}, {0, 0}};  // empty: no object
  if (!scene_->virtual_objects.empty()) {
    glm::vec2 lo(1e30f), hi(-1e30f);
    const glm::vec3 b0 = scene_->virtual_objects.bounds_min, b1 = scene_->virtual_objects.bounds_max;
    for (int k = 0; k < 8; ++k) {
      const glm::vec4 c = fc.world_to_clip * glm::vec4(k & 1 ? b1.x : b0.x, k & 2 ? b1.y : b0.y,
                                                      k & 4 ? b1.z : b0.z, 1.0f);
      if (!(c.w > 1e-4f)) {  // a corner at or behind the camera plane: no bound from projection
        lo = glm::vec2(-1e30f);
        hi = glm::vec2(1e30f);
        break;
      }
      const glm::vec2 px = (glm::vec2(c) / c.w * 0.5f + 0.5f) * glm::vec2(float(e.width), float(e.height));
      lo = glm::min(lo, px);
      hi = glm::max(hi, px);
    }
    // One pixel of margin for rasterisation rounding.
    const int x0 = int(std::clamp(std::floor(lo.x) - 1.0f, 0.0f, float(e.width)));
    const int y0 = int(std::clamp(std::floor(lo.y) - 1.0f, 0.0f, float(e.height)));
    const int x1 = int(std::clamp(std::ceil(hi.x) + 1.0f, 0.0f, float(e.width)));
    const int y1 = int(std::clamp(std::ceil(hi.y) + 1.0f, 0.0f, float(e.height)));
    if (x1 > x0 && y1 > y0) now = {{x0, y0}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
  }
  VkRect2D area = same_size ? a.previous : full;
  if (same_size && now.extent.width > 0) {
    if (area.extent.width == 0) {
      area = now;
    } else {
      const int x0 = std::min(area.offset.x, now.offset.x), y0 = std::min(area.offset.y, now.offset.y);
      const int x1 = std::max(area.offset.x + int(area.extent.width), now.offset.x + int(now.extent.width));
      const int y1 = std::max(area.offset.y + int(area.extent.height), now.offset.y + int(now.extent.height));
      area = {{x0, y0}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
    }
  }
  a.previous = now;
  // Vulkan needs a non-empty render area; a 1x1 clear of texel (0, 0) keeps it cleared.
  if (area.extent.width == 0 || area.extent.height == 0) area = {{0, 0}, {1, 1}};
  a.now = area;
}

void VirtualGBuffer::draw(VkCommandBuffer cmd, gpu::PassContext& pass) {
  const VkExtent2D e = pass.extent(position_);
  VkRenderingAttachmentInfo colors[4];
  const gpu::ImageHandle targets[4] = {position_, normal_, albedo_, emission_};
  const uint32_t count = emission_.valid() ? 4 : 3;
  for (uint32_t i = 0; i < count; ++i) colors[i] = cleared_color(pass.view(targets[i]), color_layout_);
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = pass.view(depth_);
  depth.imageLayout = depth_layout_;
  depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depth.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = area_.now;
  ri.layerCount = 1;
  ri.colorAttachmentCount = count;
  ri.pColorAttachments = colors;
  ri.pDepthAttachment = &depth;
  pass.context().fn().cmd_begin_rendering(cmd, &ri);
  if (!scene_->virtual_objects.empty()) {
    set_viewport(cmd, e, area_.now);
    const float per_pixel = 1.0f / float(std::max<uint32_t>(real_.step, 1));
    const glm::vec2 push(per_pixel);
    vkCmdPushConstants(cmd, pipeline_->layout, pipeline_->stages, kRealScaleOffset, sizeof(push), &push);
    scene_->virtual_objects.draw(cmd, pass, &*pipeline_, &*double_sided_pipeline_, &lod_);
  }
  pass.context().fn().cmd_end_rendering(cmd);
}

void VirtualGBuffer::draw_coverage(VkCommandBuffer cmd, gpu::PassContext& pass) {
  const VkExtent2D e = pass.extent(coverage_), internal = pass.extent(position_);
  VkRenderingAttachmentInfo color = cleared_color(pass.view(coverage_), color_layout_);
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = coverage_area_.now;
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &color;
  pass.context().fn().cmd_begin_rendering(cmd, &ri);
  if (!scene_->virtual_objects.empty()) {
    set_viewport(cmd, e, coverage_area_.now);
    // An output pixel's centre in internal pixels, then in real texels (step internal pixels
    // each): (p + 0.5) * internal / (output * step).
    const float step = float(std::max<uint32_t>(real_.step, 1));
    const glm::vec2 push(float(internal.width) / (float(e.width) * step),
                         float(internal.height) / (float(e.height) * step));
    vkCmdPushConstants(cmd, coverage_pipeline_->layout, coverage_pipeline_->stages, kRealScaleOffset,
                       sizeof(push), &push);
    scene_->virtual_objects.draw(cmd, pass, &*coverage_pipeline_, &*coverage_double_sided_pipeline_,
                                 &coverage_lod_);
  }
  pass.context().fn().cmd_end_rendering(cmd);
}

}  // namespace mrgi::recon
