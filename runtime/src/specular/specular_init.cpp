// The specular stage's resources: its images, buffers and pipelines (SpecularStage::Impl::init).
#include <algorithm>
#include <string>

#include "common/light_set.glsl"
#include "gpu/shaders.h"
#include "light/light_stage.h"
#include "specular/specular_internal.h"
#include "frame/scene_gpu.h"

namespace mrgi::specular {

using specular_detail::kBackNormalFormat;
using specular_detail::kDepthFormat;
using specular_detail::kImpostorAlbedoFormat;
using specular_detail::kImpostorNormalFormat;
using specular_detail::kPositionFormat;
using specular_detail::kTraceList;
using specular_detail::kTraceLists;
using specular_detail::TraceList;

Status SpecularStage::Impl::init() {
  const int sets = std::clamp(settings.max_sets, 1, MRGI_SPECULAR_MAX_SETS);
  settings.max_sets = sets;
  MRGI_TRY(create_impostor_atlases());
  MRGI_TRY(create_back_face_images());
  MRGI_TRY(create_placeholders());
  MRGI_TRY(create_face_buffers());
  MRGI_TRY(create_frame_buffers());
  MRGI_TRY(create_compute_pipelines());
  MRGI_TRY(create_trace_lists());
  MRGI_TRY(create_raster_pipelines());
  if (settings.caustics) {
    auto c = Caustics::create(shared, settings.max_caustic_map, settings.max_caustic_receiver_map, *back_pipeline);
    if (!c) return c.error();
    caustics.emplace(std::move(*c));
  }
  return ok_status();
}

Status SpecularStage::Impl::create_impostor_atlases() {
  gpu::FrameGraph& graph = *shared.graph;
  const uint32_t face = settings.max_impostor_face;
  const int sets = settings.max_sets;
  const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  auto atlas = [&](const char* name, VkFormat f, VkImageUsageFlags usage) -> Expected<gpu::ImageHandle> {
    gpu::ImageDesc d;
    d.name = name;
    d.format = f;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = 3 * face;
    d.height = 2 * face * uint32_t(sets);
    d.history = true;  // a set not redrawn this frame (SpecularLevel::refresh_period) is read as it was
    return graph.create_image(d, usage);
  };
  auto p = atlas("specular impostor position", kPositionFormat, colour);
  if (!p) return p.error();
  impostor_position = *p;
  auto n = atlas("specular impostor normal", kImpostorNormalFormat, colour);
  if (!n) return n.error();
  impostor_normal = *n;
  auto a = atlas("specular impostor albedo", kImpostorAlbedoFormat, colour);
  if (!a) return a.error();
  impostor_albedo = *a;
  auto dz = atlas("specular impostor depth", kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  if (!dz) return dz.error();
  impostor_depth = *dz;
  return ok_status();
}

Status SpecularStage::Impl::create_back_face_images() {
  gpu::FrameGraph& graph = *shared.graph;
  const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  auto screen = [&](const char* name, VkFormat f, VkImageUsageFlags usage) -> Expected<gpu::ImageHandle> {
    gpu::ImageDesc d;
    d.name = name;
    d.format = f;  // OutputRelative, following the render scale: the internal resolution
    return graph.create_image(d, usage);
  };
  auto bp = screen("specular back position", kPositionFormat, colour);
  if (!bp) return bp.error();
  back_position = *bp;
  auto bn = screen("specular back normal", kBackNormalFormat, colour);
  if (!bn) return bn.error();
  back_normal = *bn;
  auto bd = screen("specular back depth", kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  if (!bd) return bd.error();
  back_depth = *bd;
  return ok_status();
}

// What the trace binds in place of the technique's shadow maps and the caustics when there are
// none this frame.
Status SpecularStage::Impl::create_placeholders() {
  gpu::FrameGraph& graph = *shared.graph;
  gpu::ImageDesc ns;
  ns.name = "specular no shadow map";
  ns.format = kDepthFormat;
  ns.size_mode = gpu::SizeMode::Absolute;
  ns.width = ns.height = 1;
  ns.array_view = true;
  auto nsi = graph.create_image(ns, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  if (!nsi) return nsi.error();
  no_shadow = *nsi;
  // Bound as the trace's caustic buffer where the caustics ablation leaves none (flags.w 0: never
  // read), in the binding's own format.
  auto nci = graph.create_zero_image("specular no caustics", VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!nci) return nci.error();
  no_caustics = *nci;
  // The same for the receiver maps (flags.w 2 only), at levels without them.
  auto nri = graph.create_zero_image("specular no caustic receivers", VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!nri) return nri.error();
  no_receivers = *nri;
  auto nrl = graph.create_buffer({"specular no caustic receiver lamps", sizeof(shader::CausticReceivers)},
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!nrl) return nrl.error();
  no_receiver_lamps = *nrl;
  return ok_status();
}

Status SpecularStage::Impl::create_face_buffers() {
  gpu::FrameGraph& graph = *shared.graph;
  const uint32_t face = settings.max_impostor_face;
  const int sets = settings.max_sets;
  // The finest grid any level draws: a point per texel of the largest face (set_grid).
  const VkExtent2D g = graph.allocated_extent(shared.real_position);
  const uint32_t finest = std::max(1u, (std::max(g.width, g.height) + face - 1) / face);
  const uint64_t cells = uint64_t((g.width - 1) / finest) * uint64_t((g.height - 1) / finest);
  face_capacity = uint32_t(std::max<uint64_t>(3, cells * 6));
  for (int i = 0; i < sets; ++i) {
    auto fi = graph.create_buffer({"specular face indices " + std::to_string(i), VkDeviceSize(face_capacity) * 6 * 4},
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    if (!fi) return fi.error();
    face_indices.push_back(*fi);
    auto fd = graph.create_buffer({"specular face draws " + std::to_string(i), 6 * 20},
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    if (!fd) return fd.error();
    face_draws.push_back(*fd);
  }
  return ok_status();
}

// The buffers prepare() and finish() write each frame: constants, the unshadowed lights, the
// environment grid.
Status SpecularStage::Impl::create_frame_buffers() {
  gpu::FrameGraph& graph = *shared.graph;
  auto cb = graph.create_buffer({"specular constants", sizeof(shader::SpecularConstants), gpu::MemoryUsage::Upload, true},
                                VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!cb) return cb.error();
  constants = *cb;
  auto lb = graph.create_buffer({"specular lights", sizeof(shader::LightSet), gpu::MemoryUsage::Upload, true},
                                VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!lb) return lb.error();
  own_lights = *lb;
  env_width = shared.light_stage ? shared.light_stage->environment_grid_width() : 0;
  const VkDeviceSize env_cells = VkDeviceSize(std::max(env_width, 2)) * VkDeviceSize(std::max(env_width, 2) / 2);
  auto eb = graph.create_buffer({"specular environment grid", env_cells * sizeof(glm::vec4), gpu::MemoryUsage::Upload, true},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!eb) return eb.error();
  env_grid = *eb;
  return ok_status();
}

Status SpecularStage::Impl::create_compute_pipelines() {
  const gpu::Context& ctx = *shared.context;
  auto ip = gpu::load_compute_pipeline(ctx, "specular/impostor_cells.comp", {});
  if (!ip) return ip.error();
  cells_pipeline = std::move(*ip);
  auto trace_spv = gpu::shader_spirv("specular/trace.comp");
  if (!trace_spv) return trace_spv.error();
  for (int list = 0; list < kTraceLists; ++list) {
    const TraceList& l = kTraceList[list];
    auto tp = gpu::create_compute_pipeline(ctx, {l.pass, *trace_spv, {}, 0, {l.refractive ? 1u : 0u, l.reflect ? 1u : 0u}});
    if (!tp) return tp.error();
    trace_pipelines[list] = gpu::PipelineHandle(ctx, std::move(*tp));
  }
  auto lp = gpu::load_compute_pipeline(ctx, "specular/trace_list.comp", {});
  if (!lp) return lp.error();
  list_pipeline = std::move(*lp);
  return ok_status();
}

Status SpecularStage::Impl::create_trace_lists() {
  gpu::FrameGraph& graph = *shared.graph;
  // The trace's lists (trace_list.comp): every internal pixel of each kind at most.
  const VkExtent2D internal = graph.allocated_extent(shared.lit_rv);
  list_capacity = internal.width * internal.height;
  auto ta = graph.create_buffer({"specular trace args", 16 * kTraceLists}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                                  VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!ta) return ta.error();
  trace_args = *ta;
  auto tc = graph.create_buffer({"specular trace counts", 16},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!tc) return tc.error();
  trace_counts = *tc;
  auto tl = graph.create_buffer({"specular trace pixels", VkDeviceSize(list_capacity) * kTraceLists * 4},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!tl) return tl.error();
  trace_pixels = *tl;
  return ok_status();
}

// The impostors' two pipelines (the real grid, the meshes) and the back faces'.
Status SpecularStage::Impl::create_raster_pipelines() {
  const gpu::Context& ctx = *shared.context;
  auto impostor_fs = gpu::shader_spirv("specular/impostor.frag");
  if (!impostor_fs) return impostor_fs.error();
  auto back_fs = gpu::shader_spirv("specular/backface.frag");
  if (!back_fs) return back_fs.error();
  auto grid_vs = gpu::shader_spirv("gi/rsm_grid.vert");
  if (!grid_vs) return grid_vs.error();
  auto mesh_vs = gpu::shader_spirv("gi/rsm_mesh.vert");
  if (!mesh_vs) return mesh_vs.error();
  gpu::GraphicsPipelineDesc pd;
  pd.name = "specular impostor grid";
  pd.vertex_spirv = *grid_vs;
  pd.fragment_spirv = *impostor_fs;
  pd.color_formats = {kPositionFormat, kImpostorNormalFormat, kImpostorAlbedoFormat};
  pd.depth_format = kDepthFormat;
  pd.cull_mode = VK_CULL_MODE_NONE;
  auto gp = gpu::create_graphics_pipeline(ctx, pd);
  if (!gp) return gp.error();
  grid_pipeline = gpu::PipelineHandle(ctx, std::move(*gp));
  MRGI_TRY(gpu::require_bindings(*grid_pipeline, pd.name, {"real_position", "real_normal", "real_albedo", "base_color_maps"}));
  pd.name = "specular impostor mesh";
  pd.vertex_spirv = *mesh_vs;
  pd.vertex_strides = {sizeof(frame::GpuVertex)};
  pd.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, 0, VK_FORMAT_R32G32_SFLOAT, 24}};
  auto mp = gpu::create_graphics_pipeline(ctx, pd);
  if (!mp) return mp.error();
  mesh_pipeline = gpu::PipelineHandle(ctx, std::move(*mp));
  MRGI_TRY(gpu::require_bindings(*mesh_pipeline, pd.name, {"Materials", "base_color_maps"}));
  pd.name = "specular back faces";
  pd.fragment_spirv = *back_fs;
  pd.color_formats = {kPositionFormat, kBackNormalFormat};
  pd.cull_mode = VK_CULL_MODE_FRONT_BIT;
  auto bpp = gpu::create_graphics_pipeline(ctx, pd);
  if (!bpp) return bpp.error();
  back_pipeline = gpu::PipelineHandle(ctx, std::move(*bpp));
  MRGI_TRY(gpu::require_bindings(*back_pipeline, pd.name, {"Materials"}));
  return ok_status();
}

}  // namespace mrgi::specular
