#include "gi/rsm.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu/shaders.h"

namespace mrgi::gi {
namespace {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kFluxFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

glm::vec3 any_up(const glm::vec3& forward) {
  return std::abs(forward.y) > 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
}

Expected<uint32_t> binding_of(const gpu::Pipeline& p, const char* name, const std::string& what) {
  const gpu::ShaderBinding* b = p.interface.find(name);
  if (!b) return fail(ErrorKind::Internal, what + ": shader binding '" + name + "' not found");
  return b->binding;
}

}  // namespace

Expected<RsmView> rsm_view(const LightDesc& lamp, const glm::vec3& centre, float radius, uint32_t size) {
  if (!(radius > 0.0f) || size == 0) return fail(ErrorKind::BadUsage, "rsm_view: radius and size must be > 0");
  RsmView v;
  const glm::vec3 colour = lamp.color * lamp.intensity;
  v.lpv.colour = colour;
  if (lamp.type == LightType::Directional) {
    const glm::vec3 dir = glm::normalize(lamp.direction);
    // Casters up to 4 radii towards the lamp (a table above the volume still shadows it).
    const glm::vec3 eye = centre - dir * (4.0f * radius);
    const glm::mat4 view = glm::lookAt(eye, centre, any_up(dir));
    const glm::mat4 proj = glm::ortho(-radius, radius, -radius, radius, 0.0f, 5.0f * radius);
    v.view_proj = proj * view;
    const float texel = 2.0f * radius / float(size);
    v.light = glm::vec4(dir, -texel * texel);
    v.colour = glm::vec4(colour, -2.0f);
    v.axis = glm::vec4(dir, 0.0f);
    v.lpv.direction_or_position = dir;
    v.lpv.positional = false;
    v.lod = frame::orthographic_lod_view(centre, dir, texel, 0.5f);
    return v;
  }
  const glm::vec3 to_centre = centre - lamp.position;
  const float dist = glm::length(to_centre);
  glm::vec3 axis;
  float half;
  if (lamp.type == LightType::Spot) {
    // The map looks along the spot: nothing outside its cone is lit.
    axis = glm::normalize(lamp.direction);
    half = glm::radians(std::min(lamp.outer_angle_deg, 75.0f));
  } else {
    if (!(dist > 1.05f * radius))
      return fail(ErrorKind::BadUsage, "rsm_view: a point lamp at " + std::to_string(dist) +
                                           " m from the volume's centre is inside its sphere (radius " +
                                           std::to_string(radius) + " m): one perspective map cannot see it all");
    axis = to_centre / dist;
    half = std::asin(std::min(radius / dist, 0.965f));  // at most 75 degrees off the axis
  }
  const glm::mat4 view = glm::lookAt(lamp.position, lamp.position + axis, any_up(axis));
  const float far_plane = std::max(dist + radius, 0.1f);
  const glm::mat4 proj = glm::perspective(2.0f * half, 1.0f, 0.01f, far_plane);
  v.view_proj = proj * view;
  const float t = 2.0f * std::tan(half) / float(size);
  v.light = glm::vec4(lamp.position, t * t);
  const bool spot = lamp.type == LightType::Spot;
  v.colour = glm::vec4(colour, spot ? std::cos(glm::radians(lamp.outer_angle_deg)) : -2.0f);
  v.axis = glm::vec4(axis, spot ? std::cos(glm::radians(lamp.inner_angle_deg)) : 1.0f);
  v.lpv.direction_or_position = lamp.position;
  v.lpv.positional = true;
  v.lod = {lamp.position, 1.0f / t, 0.5f};
  return v;
}

Expected<ReflectiveShadowMaps> ReflectiveShadowMaps::create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                                            const RealGBuffer& real, const RsmSettings& s) {
  if (s.size < 16 || s.size > 2048) return fail(ErrorKind::BadUsage, "RsmSettings.size: must be 16..2048 texels");
  ReflectiveShadowMaps r;
  r.settings_ = s;
  r.scene_ = &scene;
  r.real_ = real;
  const char* which[2] = {" rho", " mu"};
  for (int m = 0; m < 2; ++m) {
    auto image = [&](const char* part, VkFormat f, VkImageUsageFlags usage) -> Expected<gpu::ImageHandle> {
      gpu::ImageDesc d;
      d.name = s.name + which[m] + part;
      d.format = f;
      d.size_mode = gpu::SizeMode::Absolute;
      d.width = d.height = s.size;
      return graph.create_image(d, usage);
    };
    const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    auto p = image(" position", kPositionFormat, colour);
    if (!p) return p.error();
    auto n = image(" normal", kNormalFormat, colour);
    if (!n) return n.error();
    auto f = image(" flux", kFluxFormat, colour);
    if (!f) return f.error();
    auto d = image(" depth", kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                               VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    if (!d) return d.error();
    r.maps_[m] = {*p, *n, *f, *d};
  }
  const gpu::Context& ctx = graph.context();
  // The grid's index list for the finest grid (a point a G-buffer pixel).
  const VkExtent2D g = graph.allocated_extent(real.position);
  const VkDeviceSize cells = VkDeviceSize(std::max(1u, g.width - 1)) * std::max(1u, g.height - 1);
  auto ib = graph.create_buffer({s.name + " grid indices", cells * 6 * 4},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  if (!ib) return ib.error();
  r.grid_indices_ = *ib;
  auto ip = gpu::load_compute_pipeline(ctx, "shading/shadow_caster_indices.comp", {});
  if (!ip) return ip.error();
  r.indices_pipeline_ = std::move(*ip);
  auto frag = gpu::shader_spirv("gi/rsm.frag");
  if (!frag) return frag.error();
  auto grid_vs = gpu::shader_spirv("gi/rsm_grid.vert");
  if (!grid_vs) return grid_vs.error();
  auto mesh_vs = gpu::shader_spirv("gi/rsm_mesh.vert");
  if (!mesh_vs) return mesh_vs.error();
  gpu::GraphicsPipelineDesc pd;
  pd.name = s.name + " grid";
  pd.vertex_spirv = *grid_vs;
  pd.fragment_spirv = *frag;
  pd.color_formats = {kPositionFormat, kNormalFormat, kFluxFormat};
  pd.depth_format = kDepthFormat;
  pd.cull_mode = VK_CULL_MODE_NONE;
  auto gp = gpu::create_graphics_pipeline(ctx, pd);
  if (!gp) return gp.error();
  r.grid_pipeline_ = gpu::PipelineHandle(ctx, std::move(*gp));
  MRGI_TRY(gpu::require_bindings(*r.grid_pipeline_, "rsm grid", {"real_position", "real_normal", "real_albedo", "base_color_maps"}));
  pd.name = s.name + " mesh";
  pd.vertex_spirv = *mesh_vs;
  pd.vertex_strides = {sizeof(frame::GpuVertex)};
  pd.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, 0, VK_FORMAT_R32G32_SFLOAT, 24}};
  auto mp = gpu::create_graphics_pipeline(ctx, pd);
  if (!mp) return mp.error();
  r.mesh_pipeline_ = gpu::PipelineHandle(ctx, std::move(*mp));
  MRGI_TRY(gpu::require_bindings(*r.mesh_pipeline_, "rsm mesh", {"Materials", "base_color_maps"}));
  // The draw pushes these by name: check once that the shaders declare them.
  for (const char* name : {"real_position", "real_normal", "real_albedo", "base_color_maps"})
    if (auto b = binding_of(*r.grid_pipeline_, name, pd.name); !b) return b.error();
  for (const char* name : {"Materials", "base_color_maps"})
    if (auto b = binding_of(*r.mesh_pipeline_, name, pd.name); !b) return b.error();
  return r;
}

void ReflectiveShadowMaps::add_grid(gpu::FrameGraph& graph, uint32_t stride) {
  const VkExtent2D g = graph.extent(real_.position);
  grid_stride_ = std::max(1u, stride);
  grid_points_ = {(g.width - 1) / grid_stride_ + 1, (g.height - 1) / grid_stride_ + 1};
  const VkExtent2D points = grid_points_;
  const uint32_t st = grid_stride_;
  const gpu::Pipeline* pipe = &*indices_pipeline_;
  const VkSampler nearest = graph.context().samplers().nearest_clamp;
  graph.add_shader_pass(
      settings_.name + " grid", gpu::PassKind::Compute, *indices_pipeline_,
      [this, nearest](gpu::ShaderPassBuilder& b) {
        b.bind_sampled("real_position", real_.position, nearest);
        b.bind("Indices", grid_indices_);
      },
      [pipe, points, st](VkCommandBuffer cmd, gpu::PassContext&) {
        const glm::ivec4 push(int(points.width), int(points.height), int(st), 0);
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push,
                               {(points.width - 1 + 7) / 8, (points.height - 1 + 7) / 8, 1});
      });
}

RsmImages ReflectiveShadowMaps::images(RsmMap map, uint32_t size) const {
  const Maps& m = maps_[map == RsmMap::WithVirtual ? 0 : 1];
  return {m.position, m.normal, m.flux, std::min(size, settings_.size), std::min(size, settings_.size)};
}

bool lamp_reaches_sphere(const LightDesc& lamp, const glm::vec3& centre, float radius) {
  if (lamp.type != LightType::Spot) return true;
  const glm::vec3 to = centre - lamp.position;
  const float d = glm::length(to);
  if (d <= radius) return true;
  const float axis_len = glm::length(lamp.direction);
  if (!(axis_len > 0.0f)) return true;
  // The sphere meets the cone when its centre is within the cone's half-angle plus the angle the
  // sphere subtends from the apex.
  const float angle = std::acos(std::clamp(glm::dot(to / d, lamp.direction / axis_len), -1.0f, 1.0f));
  return angle <= glm::radians(std::clamp(lamp.outer_angle_deg, 0.0f, 180.0f)) + std::asin(radius / d);
}

void ReflectiveShadowMaps::add_real(gpu::FrameGraph& graph, const std::string& id, const RsmView& view, uint32_t size) {
  add_map_draw(graph, "mu " + id, view, maps_[1], std::min(size, settings_.size), true, false);
}

void ReflectiveShadowMaps::add_pair(gpu::FrameGraph& graph, const std::string& id, const RsmView& view,
                                    uint32_t size) {
  const uint32_t s = std::min(size, settings_.size);
  add_map_draw(graph, "mu " + id, view, maps_[1], s, true, false);
  const Maps from = maps_[1], to = maps_[0];
  graph.add_pass(
      settings_.name + " rho copy " + id, gpu::PassKind::Transfer,
      [from, to](gpu::PassBuilder& b) {
        for (gpu::ImageHandle h : {from.position, from.normal, from.flux, from.depth}) b.read(h, gpu::Access::TransferSrc);
        for (gpu::ImageHandle h : {to.position, to.normal, to.flux, to.depth}) b.write(h, gpu::Access::TransferDst);
      },
      [from, to, s](VkCommandBuffer cmd, gpu::PassContext& p) {
        const gpu::ImageHandle src[4] = {from.position, from.normal, from.flux, from.depth};
        const gpu::ImageHandle dst[4] = {to.position, to.normal, to.flux, to.depth};
        for (int i = 0; i < 4; ++i) {
          VkImageCopy region{};
          region.srcSubresource = {i == 3 ? VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT) : VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT), 0, 0, 1};
          region.dstSubresource = region.srcSubresource;
          region.extent = {s, s, 1};
          vkCmdCopyImage(cmd, p.image(src[i]), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.image(dst[i]),
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        }
      });
  add_map_draw(graph, "rho " + id, view, maps_[0], s, false, true);
}

void ReflectiveShadowMaps::add_map_draw(gpu::FrameGraph& graph, const std::string& label, const RsmView& view,
                                        const Maps& m, uint32_t s, bool real_casters, bool virtual_casters) {
  const frame::SceneGpu* sg = scene_;
  const bool grid = real_casters && grid_points_.width > 1 && grid_points_.height > 1;
  const uint32_t grid_indices = grid ? (grid_points_.width - 1) * (grid_points_.height - 1) * 6 : 0;
  const bool virtuals = virtual_casters && !sg->virtual_objects.empty();
  const bool proxies = real_casters && !sg->real_proxies.empty();
  // Over the real casters' copy (add_pair) the attachments are loaded, not cleared.
  const VkAttachmentLoadOp load = real_casters ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
  const RealGBuffer real = real_;
  const gpu::BufferHandle indices = grid_indices_;
  const gpu::Pipeline* grid_pipe = &*grid_pipeline_;
  const gpu::Pipeline* mesh_pipe = &*mesh_pipeline_;
  const frame::LodView lod = view.lod;
  RsmPush push{view.view_proj, view.light, view.colour, view.axis,
               glm::ivec4(int(grid_stride_), -1, 0, int(grid_points_.width))};
  graph.add_pass(
      settings_.name + " " + label, gpu::PassKind::Graphics,
      [=](gpu::PassBuilder& b) {
        if (grid_indices > 0) {
          b.read(real.position, gpu::Access::Sampled);
          b.read(real.normal, gpu::Access::Sampled);
          b.read(real.albedo, gpu::Access::Sampled);
          b.read(indices, gpu::Access::IndexBuffer);
        }
        if (proxies) {
          b.read(sg->real_proxies.vertices, gpu::Access::VertexBuffer);
          b.read(sg->real_proxies.indices, gpu::Access::IndexBuffer);
        }
        if (virtuals) {
          b.read(sg->virtual_objects.vertices, gpu::Access::VertexBuffer);
          b.read(sg->virtual_objects.indices, gpu::Access::IndexBuffer);
        }
        if (proxies || virtuals) b.read(sg->materials, gpu::Access::StorageRead);
        b.read(sg->base_color_maps, gpu::Access::Sampled);
        if (real_casters) {
          b.write(m.position, gpu::Access::ColorAttachmentWrite);
          b.write(m.normal, gpu::Access::ColorAttachmentWrite);
          b.write(m.flux, gpu::Access::ColorAttachmentWrite);
          b.write(m.depth, gpu::Access::DepthAttachmentWrite);
        } else {  // drawn over the copy of the real casters' map
          b.write(m.position, gpu::Access::ColorAttachmentReadWrite);
          b.write(m.normal, gpu::Access::ColorAttachmentReadWrite);
          b.write(m.flux, gpu::Access::ColorAttachmentReadWrite);
          b.write(m.depth, gpu::Access::DepthAttachmentReadWrite);
        }
      },
      [=](VkCommandBuffer cmd, gpu::PassContext& p) mutable {
        const gpu::Context& ctx = p.context();
        const VkImageLayout colour_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        VkRenderingAttachmentInfo colour[3];
        const gpu::ImageHandle targets[3] = {m.position, m.normal, m.flux};
        for (int i = 0; i < 3; ++i) {
          colour[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
          colour[i].imageView = p.view(targets[i]);
          colour[i].imageLayout = colour_layout;
          colour[i].loadOp = load;
          colour[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
          colour[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
        }
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = p.view(m.depth);
        depth.imageLayout = gpu::access_info(gpu::PassKind::Graphics,
                                             real_casters ? gpu::Access::DepthAttachmentWrite : gpu::Access::DepthAttachmentReadWrite,
                                             true, true).layout;
        depth.loadOp = load;
        // R^mu's depth is copied into R^rho (add_pair); R^rho's own is not read after the draw.
        depth.storeOp = real_casters ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{0, 0}, {s, s}};
        ri.layerCount = 1;
        ri.colorAttachmentCount = 3;
        ri.pColorAttachments = colour;
        ri.pDepthAttachment = &depth;
        ctx.fn().cmd_begin_rendering(cmd, &ri);
        const VkViewport vp{0.0f, 0.0f, float(s), float(s), 0.0f, 1.0f};
        const VkRect2D sc{{0, 0}, {s, s}};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &sc);
        RsmGeometryDraw g;
        g.grid_pipeline = grid_indices > 0 ? grid_pipe : nullptr;
        g.mesh_pipeline = mesh_pipe;
        g.real = real;
        g.grid_indices = indices;
        g.grid_index_count = grid_indices;
        g.proxies = proxies;
        g.virtuals = virtuals;
        g.lod = &lod;
        draw_rsm_geometry(cmd, p, *sg, g, push);
        ctx.fn().cmd_end_rendering(cmd);
      });
}

namespace {
// Whether the box's eight corners are all outside one of the clip volume's planes (Vulkan clip:
// -w <= x, y <= w, 0 <= z <= w).
bool outside_clip(const glm::mat4& view_proj, const glm::vec3& lo, const glm::vec3& hi) {
  int out[6] = {0, 0, 0, 0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    const glm::vec4 q = view_proj * glm::vec4(p, 1.0f);
    out[0] += q.x < -q.w;
    out[1] += q.x > q.w;
    out[2] += q.y < -q.w;
    out[3] += q.y > q.w;
    out[4] += q.z < 0.0f;
    out[5] += q.z > q.w;
  }
  for (int k = 0; k < 6; ++k)
    if (out[k] == 8) return true;
  return false;
}
}  // namespace

void draw_rsm_geometry(VkCommandBuffer cmd, gpu::PassContext& p, const frame::SceneGpu& scene,
                       const RsmGeometryDraw& d, RsmPush push) {
  const gpu::Context& ctx = p.context();
  const VkSampler linear = ctx.samplers().linear_repeat, nearest = ctx.samplers().nearest_clamp;
  if (d.grid_pipeline) {
    const gpu::Pipeline* gp = d.grid_pipeline;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, gp->pipeline);
    const gpu::ShaderInterface& gi = gp->interface;
    gpu::DescriptorPush()
        .sampled_image(gi.find("real_position")->binding, p.view(d.real.position), nearest)
        .sampled_image(gi.find("real_normal")->binding, p.view(d.real.normal), nearest)
        .sampled_image(gi.find("real_albedo")->binding, p.view(d.real.albedo), nearest)
        .sampled_image(gi.find("base_color_maps")->binding, p.view(scene.base_color_maps), linear)
        .push(ctx, cmd, *gp);
    vkCmdPushConstants(cmd, gp->layout, gp->stages, 0, sizeof push, &push);
    vkCmdBindIndexBuffer(cmd, p.buffer(d.grid_indices), 0, VK_INDEX_TYPE_UINT32);
    if (d.grid_indirect.valid())
      vkCmdDrawIndexedIndirect(cmd, p.buffer(d.grid_indirect), d.grid_indirect_offset, 1, 20);
    else
      vkCmdDrawIndexed(cmd, d.grid_index_count, 1, 0, 0, 0);
  }
  const bool proxies = d.proxies && !scene.real_proxies.empty();
  const bool virtuals = d.virtuals && !scene.virtual_objects.empty();
  if (!d.mesh_pipeline || !(proxies || virtuals)) return;
  const gpu::Pipeline* mp = d.mesh_pipeline;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mp->pipeline);
  const gpu::ShaderInterface& mi = mp->interface;
  gpu::DescriptorPush()
      .storage_buffer(mi.find("Materials")->binding, p.buffer(scene.materials))
      .sampled_image(mi.find("base_color_maps")->binding, p.view(scene.base_color_maps), linear)
      .push(ctx, cmd, *mp);
  auto draw_set = [&](const frame::MeshSet& set, bool materials) {
    VkBuffer vb = p.buffer(set.vertices);
    VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
    vkCmdBindIndexBuffer(cmd, p.buffer(set.indices), 0, VK_INDEX_TYPE_UINT32);
    for (size_t i = 0; i < set.draws.size(); ++i) {
      if (materials && d.skip_virtual && i < d.skip_virtual->size() && (*d.skip_virtual)[i]) continue;
      const frame::DrawRange& r = set.draws[i];
      if (d.cull_view_proj && outside_clip(*d.cull_view_proj, r.bounds_min, r.bounds_max)) continue;
      // Proxies: their scene.json material hint is not on the GPU yet: mid grey.
      push.misc.y = materials ? r.material : -1;
      push.misc.z = materials ? 0 : int(0xff808080u);
      vkCmdPushConstants(cmd, mp->layout, mp->stages, 0, sizeof push, &push);
      const frame::DrawRange::Lod l =
          r.lods.empty() || !d.lod ? frame::DrawRange::Lod{r.first_index, r.index_count, 0.0f}
                                   : r.lods[frame::MeshSet::select_lod(r, *d.lod)];
      vkCmdDrawIndexed(cmd, l.index_count, 1, l.first_index, r.vertex_offset, 0);
    }
  };
  if (proxies) draw_set(scene.real_proxies, false);
  if (virtuals) draw_set(scene.virtual_objects, true);
}

}  // namespace mrgi::gi
