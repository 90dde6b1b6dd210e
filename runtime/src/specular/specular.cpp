#include "specular/specular.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "common/light_set.glsl"
#include "gi/rsm.h"
#include "gpu/shaders.h"
#include "light/env_sampler.h"
#include "light/light_stage.h"
#include "shared/specular_math.h"
#include "specular/caustics.h"
#include "specular/mesh_raster.h"
#include "specular/specular_params.glsl"
#include "light/light_set_writer.h"
#include "frame/scene_gpu.h"
#include "frame/screen_bounds.h"

namespace mrgi::specular {
namespace {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kImpostorNormalFormat = VK_FORMAT_R8G8B8A8_SNORM;
constexpr VkFormat kImpostorAlbedoFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kBackNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
// What the impostors see: nearer than this is inside the object, farther is environment.
constexpr float kImpostorNear_m = 0.01f, kImpostorFar_m = 50.0f;

// Face f of a cube around `centre`: Vulkan clip coordinates whose x / w and y / w are
// shared/specular_math.h's face coordinates (dot(d, right) / dot(d, forward), the same with down).
glm::mat4 face_view_proj(const glm::vec3& centre, int face) {
  const glm::vec3 r = shader::specular_face_right(face), d = shader::specular_face_down(face),
                  f = shader::specular_face_forward(face);
  const float n = kImpostorNear_m, far = kImpostorFar_m;
  const float a = far / (far - n), b = -far * n / (far - n);
  // Rows: x = r . (p - c), y = d . (p - c), z = a (f . (p - c)) + b, w = f . (p - c).
  glm::mat4 m(0.0f);
  for (int c = 0; c < 3; ++c) {
    m[c][0] = r[c];
    m[c][1] = d[c];
    m[c][2] = a * f[c];
    m[c][3] = f[c];
  }
  m[3][0] = -glm::dot(r, centre);
  m[3][1] = -glm::dot(d, centre);
  m[3][2] = -a * glm::dot(f, centre) + b;
  m[3][3] = -glm::dot(f, centre);
  return m;
}

struct ObjectInView {
  size_t object = 0;
  glm::vec3 lo{0.0f}, hi{0.0f};
  float distance = 0.0f;
  bool refractive = false, reflective = false;
  frame::ScreenBounds screen;  // its box projected into this frame's camera
};

// trace_list.comp's lists, in its order: the pass over each and trace.comp's specialisation.
struct TraceList {
  const char* pass;
  bool refractive, reflect;
};
constexpr int kTraceLists = 3;
constexpr TraceList kTraceList[kTraceLists] = {{"specular trace glass", true, true},
                                               {"specular trace mirrors", false, true},
                                               {"specular trace glass unreflected", true, false}};

struct ImpostorSet {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
  std::vector<size_t> objects;  // not drawn into their own set
};

}  // namespace

struct SpecularStage::Impl {
  frame::FrameResources shared;
  SpecularSettings settings;
  gpu::ImageHandle impostor_position, impostor_normal, impostor_albedo, impostor_depth;
  gpu::ImageHandle back_position, back_normal, back_depth;
  gpu::ImageHandle no_shadow, no_caustics, no_receivers;
  gpu::BufferHandle constants, own_lights, no_receiver_lamps;
  // Per set: the real grid's triangles of each cube face (impostor_cells.comp) and the six
  // indexed indirect draws; capacity: indices a face can hold (every triangle of the finest grid).
  std::vector<gpu::BufferHandle> face_indices, face_draws;
  uint32_t face_capacity = 0;
  gpu::BufferHandle env_grid;  // the light stage's environment grid, copied each frame
  int env_width = 0;           // its width in cells
  gpu::PipelineHandle cells_pipeline, grid_pipeline, mesh_pipeline, back_pipeline, list_pipeline;
  gpu::PipelineHandle trace_pipelines[kTraceLists];  // trace.comp per kTraceList
  // trace_list.comp's output: dispatch arguments per kind (glass, mirrors), counts, pixels.
  gpu::BufferHandle trace_args, trace_counts, trace_pixels;
  uint32_t list_capacity = 0;  // pixels each kind's list holds
  std::optional<Caustics> caustics;  // null with SpecularSettings::caustics off
  bool caustics_recorded = false;    // this frame's prepare() splatted caustics
  bool active = false;               // prepare() found something to do this frame
  glm::ivec4 region{0};              // the trace list's dispatch: first pixel, size
  bool glass_in_view = false, mirrors_in_view = false;
  float glass_reflection_fresnel = 0.0f;  // this frame's level's (SpecularLevel)
  frame::CausticPhotons photons; // this frame's, for the technique
  VkExtent2D grid_points{0, 0};
  uint32_t grid_stride = 1;
  glm::mat4 world_to_clip{1.0f};  // this frame's camera (the back faces' draw)
  glm::vec3 camera_world{0.0f};   // and its centre and focal length (internal pixels)
  float internal_focal_px = 0.0f;
  // What each set's block of the atlas holds: drawn at frame `frame` around `centre` for
  // `objects` at face size `face` (a set is redrawn when any of them changed or it is
  // refresh_period frames old).
  struct DrawnSet {
    int64_t frame = -1000000;
    glm::vec3 centre{0.0f};
    std::vector<size_t> objects;
    uint32_t face = 0;
    uint64_t revision = 0;
  };
  std::vector<DrawnSet> drawn;
  int64_t frame = 0;
  // prepare()'s scratch, kept between frames (no allocation a frame once grown).
  std::vector<ObjectInView> in_view;
  std::vector<ImpostorSet> sets;
  std::vector<bool> redraw;
  std::vector<size_t> objects;

  Status init();
  void set_grid(gpu::FrameGraph& graph, uint32_t face);
  void add_impostors(gpu::FrameGraph& graph, const ImpostorSet& set, int index, const glm::ivec2& origin,
                     uint32_t face, bool first);
  void add_back_faces(gpu::FrameGraph& graph, const std::vector<ObjectInView>& objects, const glm::ivec4& region);
};

Status SpecularStage::Impl::init() {
  gpu::FrameGraph& graph = *shared.graph;
  const gpu::Context& ctx = *shared.context;
  const uint32_t face = settings.max_impostor_face;
  const int sets = std::clamp(settings.max_sets, 1, MRGI_SPECULAR_MAX_SETS);
  settings.max_sets = sets;
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
  if (settings.caustics) {
    auto c = Caustics::create(shared, settings.max_caustic_map, settings.max_caustic_receiver_map, *back_pipeline);
    if (!c) return c.error();
    caustics.emplace(std::move(*c));
  }
  return ok_status();
}

void SpecularStage::Impl::set_grid(gpu::FrameGraph& graph, uint32_t face) {
  const VkExtent2D g = graph.extent(shared.real_position);
  // At least one grid point per impostor texel across the real G-buffer's larger side (a face's
  // 90 degrees see about as much as the camera's view). Coarser grids lose the small real
  // objects near the mirror or glass: the grid drops its cells across a depth edge, and a 5
  // pixel cell is the whole top of a 16-pixel box (glass_mirror at half resolution: a stride of
  // 5 instead of 3 took the glass's RDE from 0.50 to 0.77).
  const uint32_t side = std::max(g.width, g.height);
  grid_stride = std::max(1u, (side + face - 1) / std::max(1u, face));
  grid_points = {(g.width - 1) / grid_stride + 1, (g.height - 1) / grid_stride + 1};
}

void SpecularStage::Impl::add_impostors(gpu::FrameGraph& graph, const ImpostorSet& set, int index,
                                        const glm::ivec2& origin, uint32_t face, bool first) {
  const frame::SceneGpu* sg = shared.scene_gpu;
  const std::string id = std::to_string(index);
  const bool grid = grid_points.width > 1 && grid_points.height > 1 &&
                    uint64_t(grid_points.width - 1) * (grid_points.height - 1) * 6 <= face_capacity;
  const gpu::BufferHandle indices = face_indices[size_t(index)], draws = face_draws[size_t(index)];
  if (grid) {
    // The real grid's triangles of each face, seen from this set's centre.
    graph.add_pass("specular impostor cells reset " + id, gpu::PassKind::Transfer,
                   [draws](gpu::PassBuilder& b) { b.write(draws, gpu::Access::TransferDst); },
                   [draws](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(draws), 0, 6 * 20, 0); });
    const VkSampler nearest = shared.context->samplers().nearest_clamp;
    const gpu::Pipeline* pipe = &*cells_pipeline;
    struct CellsPush {
      glm::ivec4 grid;
      glm::vec4 centre;
    } push{glm::ivec4(int(grid_points.width), int(grid_points.height), int(grid_stride), int(face_capacity)),
           glm::vec4(set.centre, 0.0f)};
    const VkExtent2D points = grid_points;
    graph.add_shader_pass(
        "specular impostor cells " + id, gpu::PassKind::Compute, *cells_pipeline,
        [this, nearest, indices, draws](gpu::ShaderPassBuilder& b) {
          b.bind_sampled("real_position", shared.real_position, nearest);
          b.bind("FaceIndices", indices);
          b.bind_over("FaceDraws", draws);
        },
        [pipe, push, points](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(points.width - 1 + 7) / 8, (points.height - 1 + 7) / 8, 1});
        });
  }
  const std::string label = "specular impostors " + id;
  std::vector<bool> excluded(sg->virtual_objects.draws.size(), false);
  for (size_t o : set.objects) {
    const frame::SceneGpu::DrawSpan span = sg->object_draws(o);
    for (size_t d = span.first; d < span.first + span.count; ++d) excluded[d] = true;
  }
  const Impl* self = this;
  const gpu::Access colour_access = first ? gpu::Access::ColorAttachmentWrite : gpu::Access::ColorAttachmentReadWrite;
  const gpu::Access depth_access = first ? gpu::Access::DepthAttachmentWrite : gpu::Access::DepthAttachmentReadWrite;
  const frame::RealGeometry real{shared.real_position, shared.real_normal, 1};
  const glm::vec3 centre = set.centre;
  const glm::ivec4 misc(int(grid_stride), -1, int(0xff808080u), int(grid_points.width));
  graph.add_pass(
      label, gpu::PassKind::Graphics,
      [=](gpu::PassBuilder& b) {
        if (grid) {
          b.read(self->shared.real_position, gpu::Access::Sampled);
          b.read(self->shared.real_normal, gpu::Access::Sampled);
          b.read(self->shared.real_albedo, gpu::Access::Sampled);
          b.read(indices, gpu::Access::IndexBuffer);
          b.read(draws, gpu::Access::IndirectRead);
        }
        if (!sg->real_proxies.empty()) {
          b.read(sg->real_proxies.vertices, gpu::Access::VertexBuffer);
          b.read(sg->real_proxies.indices, gpu::Access::IndexBuffer);
        }
        b.read(sg->virtual_objects.vertices, gpu::Access::VertexBuffer);
        b.read(sg->virtual_objects.indices, gpu::Access::IndexBuffer);
        b.read(sg->materials, gpu::Access::StorageRead);
        b.read(sg->base_color_maps, gpu::Access::Sampled);
        b.write(self->impostor_position, colour_access);
        b.write(self->impostor_normal, colour_access);
        b.write(self->impostor_albedo, colour_access);
        b.write(self->impostor_depth, depth_access);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext& p) {
        const gpu::Context& ctx = p.context();
        VkRenderingAttachmentInfo colour[3];
        const gpu::ImageHandle targets[3] = {self->impostor_position, self->impostor_normal, self->impostor_albedo};
        for (int i = 0; i < 3; ++i) {
          colour[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
          colour[i].imageView = p.view(targets[i]);
          colour[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
          colour[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // the render area: this set's block
          colour[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
          colour[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
        }
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = p.view(self->impostor_depth);
        depth.imageLayout = gpu::access_info(gpu::PassKind::Graphics, depth_access, true, true).layout;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{origin.x, origin.y}, {3 * face, 2 * face}};
        ri.layerCount = 1;
        ri.colorAttachmentCount = 3;
        ri.pColorAttachments = colour;
        ri.pDepthAttachment = &depth;
        ctx.fn().cmd_begin_rendering(cmd, &ri);
        gi::RsmGeometryDraw g;
        g.grid_pipeline = grid ? &*self->grid_pipeline : nullptr;
        g.mesh_pipeline = &*self->mesh_pipeline;
        g.real = {real.position, self->shared.real_normal, self->shared.real_albedo};
        g.grid_indices = indices;
        g.grid_indirect = draws;
        g.skip_virtual = &excluded;
        // Each face draws the meshes at the detail its texels resolve (90 degrees over `face`
        // texels: a focal length of face / 2) and only those inside its frustum.
        const frame::LodView lod{centre, 0.5f * float(face), 1.0f};
        g.lod = &lod;
        for (int f = 0; f < 6; ++f) {
          const int fx = origin.x + int(face) * (f % 3), fy = origin.y + int(face) * (f / 3);
          const VkViewport vp{float(fx), float(fy), float(face), float(face), 0.0f, 1.0f};
          const VkRect2D sc{{fx, fy}, {face, face}};
          vkCmdSetViewport(cmd, 0, 1, &vp);
          vkCmdSetScissor(cmd, 0, 1, &sc);
          g.grid_indirect_offset = VkDeviceSize(f) * 20;
          const glm::mat4 view_proj = face_view_proj(centre, f);
          g.cull_view_proj = &view_proj;
          const gi::RsmPush push{view_proj, glm::vec4(centre, 1.0f), glm::vec4(1.0f, 1.0f, 1.0f, -2.0f),
                                 glm::vec4(shader::specular_face_forward(f), 1.0f), misc};
          gi::draw_rsm_geometry(cmd, p, *sg, g, push);
        }
        ctx.fn().cmd_end_rendering(cmd);
      });
}

void SpecularStage::Impl::add_back_faces(gpu::FrameGraph& graph, const std::vector<ObjectInView>& objects,
                                          const glm::ivec4& region) {
  std::vector<size_t> refractive;
  for (const ObjectInView& o : objects)
    if (o.refractive) refractive.push_back(o.object);
  MeshRaster r;
  r.name = "specular back faces";
  r.pipeline = &*back_pipeline;
  r.colour = {back_position, back_normal};
  r.depth = back_depth;
  r.push.view_proj = world_to_clip;
  r.draws = specular_draws(*shared.scene_gpu, refractive, 1 << shader::SPECULAR_REFRACTIVE);
  // Drawn (and cleared) over the objects' projected boxes only, which hold every back face; the
  // trace reads nothing outside them (SpecularConstants::back_rect). The whole internal frame's
  // clears were most of this pass on lavapipe.
  if (region.z > 0 && region.w > 0) r.area = VkRect2D{{region.x, region.y}, {uint32_t(region.z), uint32_t(region.w)}};
  // Half an internal pixel: the finest the virtual G-buffer's front faces are drawn at.
  r.lod = frame::LodView{camera_world, internal_focal_px, 0.5f};
  add_mesh_raster(graph, *shared.scene_gpu, r);
}

SpecularStage::SpecularStage(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SpecularStage::~SpecularStage() = default;

Expected<std::unique_ptr<SpecularStage>> SpecularStage::create(const frame::FrameResources& shared,
                                                               const SpecularSettings& settings) {
  if (!shared.scene_gpu || !shared.scene_gpu->specular) return std::unique_ptr<SpecularStage>();
  if (settings.max_impostor_face < 16 || settings.max_impostor_face > 2048)
    return fail(ErrorKind::BadUsage, "SpecularSettings.max_impostor_face: must be 16..2048 texels");
  if (!(settings.depth_tolerance > 0.0f && settings.depth_tolerance < 1.0f))
    return fail(ErrorKind::BadUsage, "SpecularSettings.depth_tolerance: must be in (0, 1)");
  auto impl = std::make_unique<Impl>();
  impl->shared = shared;
  impl->settings = settings;
  MRGI_TRY(impl->init());
  return std::unique_ptr<SpecularStage>(new SpecularStage(std::move(impl)));
}

Status SpecularStage::prepare(const shader::FrameConstants& fc, int technique_level, int technique_levels,
                              std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  m.active = false;
  m.photons = frame::CausticPhotons{};
  const frame::SceneGpu& sg = *m.shared.scene_gpu;
  gpu::FrameGraph& graph = *m.shared.graph;
  std::vector<ObjectInView>& in_view = m.in_view;
  in_view.clear();
  for (size_t o = 0; o < sg.object_count(); ++o) {
    if (!sg.visible(o)) continue;
    const int kinds = sg.object_specular_kinds(o);
    if (kinds == 0) continue;
    const frame::SceneGpu::DrawSpan span = sg.object_draws(o);
    if (span.count == 0) continue;
    ObjectInView v;
    v.object = o;
    v.lo = glm::vec3(1e30f);
    v.hi = glm::vec3(-1e30f);
    for (size_t d = span.first; d < span.first + span.count; ++d) {
      v.lo = glm::min(v.lo, sg.virtual_objects.draws[d].bounds_min);
      v.hi = glm::max(v.hi, sg.virtual_objects.draws[d].bounds_max);
    }
    v.screen = frame::project_box(fc, v.lo, v.hi);
    if (!v.screen.visible) continue;
    v.distance = glm::distance(0.5f * (v.lo + v.hi), glm::vec3(fc.camera_world));
    v.refractive = (kinds & (1 << shader::SPECULAR_REFRACTIVE)) != 0;
    v.reflective = (kinds & (1 << shader::SPECULAR_REFLECTIVE)) != 0;
    in_view.push_back(v);
  }
  glm::vec2 lo_px(1e30f), hi_px(-1e30f);
  bool behind = false;
  for (const ObjectInView& v : in_view) {
    const frame::ScreenBounds& b = v.screen;
    behind = behind || b.behind;
    lo_px = glm::min(lo_px, b.min);
    hi_px = glm::max(hi_px, b.max);
  }
  m.caustics_recorded = false;
  if (in_view.empty()) {
    skipped.push_back("specular: no reflective or refractive object in view");
    return ok_status();
  }
  // The objects' projected boxes (all of the image when a corner is behind the camera): the
  // trace's dispatch, and the part of the back faces' buffers drawn and read.
  const glm::ivec2 size(fc.internal_output_size.x, fc.internal_output_size.y);
  glm::ivec2 r0(0), r1 = size;
  if (!behind) {
    r0 = glm::clamp(glm::ivec2(glm::floor(lo_px)) - 1, glm::ivec2(0), size);
    r1 = glm::clamp(glm::ivec2(glm::ceil(hi_px)) + 2, glm::ivec2(0), size);
  }
  m.region = glm::ivec4(r0, glm::max(r1 - r0, glm::ivec2(0)));
  std::sort(in_view.begin(), in_view.end(), [](const ObjectInView& a, const ObjectInView& b) { return a.distance < b.distance; });
  const SpecularLevel& level = specular_level_for(technique_level, technique_levels);
  const uint32_t face = std::min(level.impostor_face, m.settings.max_impostor_face);
  const int set_count = std::clamp(std::min(level.own_sets, m.settings.max_sets), 1, int(in_view.size()));
  std::vector<ImpostorSet>& sets = m.sets;
  sets.resize(static_cast<size_t>(set_count));
  for (ImpostorSet& s : sets) s.objects.clear();
  for (size_t i = 0; i < in_view.size(); ++i) {
    ImpostorSet& s = sets[std::min(i, size_t(set_count - 1))];
    s.objects.push_back(in_view[i].object);
  }
  for (ImpostorSet& s : sets) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (size_t o : s.objects)
      for (const ObjectInView& v : in_view)
        if (v.object == o) {
          lo = glm::min(lo, v.lo);
          hi = glm::max(hi, v.hi);
        }
    s.centre = 0.5f * (lo + hi);
    s.radius = 0.5f * glm::length(hi - lo);
  }

  // This frame's constants.
  auto* c = static_cast<shader::SpecularConstants*>(graph.mapped(m.constants, graph.slot()));
  *c = shader::SpecularConstants{};
  c->counts = glm::ivec4(set_count, level.search_steps, level.refine_steps, level.back_face_steps);
  c->params = glm::vec4(m.settings.depth_tolerance, m.shared.compose_eps, m.shared.compose_alpha_max,
                        m.settings.back_projection ? 1.0f : 0.0f);
  for (int i = 0; i < set_count; ++i) {
    c->sets[i].centre = glm::vec4(sets[size_t(i)].centre, sets[size_t(i)].radius);
    c->sets[i].atlas = glm::ivec4(0, int(2 * face) * i, int(face), 0);
  }
  const light::Lighting& lighting = m.shared.light_stage->lighting();
  for (int k = 0; k < 16; ++k) {
    glm::dvec3 e = lighting.ambient_real[size_t(k)] + lighting.ambient_virtual[size_t(k)];
    for (size_t l = 0; l < lighting.lights.size(); ++l)
      if (l < lighting.foldable.size() && lighting.foldable[l] != 0 && l < lighting.light_sh.size())
        e += lighting.light_sh[l][size_t(k)];
    c->env_sh[k] = glm::vec4(glm::vec3(e), 0.0f);
  }
  int env_width = 0;
  if (const light::EnvSampler* env = m.shared.light_stage->environment_grid();
      env && env->settings().grid_width == m.env_width) {
    env_width = m.env_width;
    auto* cells = static_cast<glm::vec4*>(graph.mapped(m.env_grid, graph.slot()));
    for (int y = 0; y < env->grid_height(); ++y)
      for (int x = 0; x < env_width; ++x) cells[size_t(y) * size_t(env_width) + size_t(x)] = glm::vec4(glm::vec3(env->cell_radiance(x, y)), 0.0f);
  }
  c->flags = glm::ivec4(0, m.settings.depth_test ? 1 : 0, env_width, 0);  // x: finish()
  c->level = glm::vec4(float(std::max(level.glass_reflection_stride, 1)), level.glass_reflection_fresnel, 0.0f, 0.0f);
  // Where add_back_faces draws (its render area; all of the frame for an empty box).
  c->back_rect = m.region.z > 0 && m.region.w > 0
                     ? glm::ivec4(m.region.x, m.region.y, m.region.x + m.region.z, m.region.y + m.region.w)
                     : glm::ivec4(0, 0, size.x, size.y);

  m.world_to_clip = fc.world_to_clip;
  m.camera_world = glm::vec3(fc.camera_world);
  m.internal_focal_px = fc.internal_k.x;
  m.set_grid(graph, face);
  // Redraw the sets whose content changed; of the rest, the oldest one if it is refresh_period
  // frames old (at most one stale set is refreshed a frame: the fast level spreads the sets over
  // frames).
  m.drawn.resize(size_t(m.settings.max_sets));
  ++m.frame;
  std::vector<bool>& redraw = m.redraw;
  redraw.assign(size_t(set_count), false);
  int oldest = -1;
  for (int i = 0; i < set_count; ++i) {
    const Impl::DrawnSet& d = m.drawn[size_t(i)];
    const ImpostorSet& s = sets[size_t(i)];
    const bool changed = d.objects != s.objects || d.face != face || d.revision != sg.revision() ||
                         glm::any(glm::greaterThan(glm::abs(d.centre - s.centre), glm::vec3(1e-5f)));
    if (changed || level.refresh_period <= 1) redraw[size_t(i)] = true;
    else if (m.frame - d.frame >= level.refresh_period && (oldest < 0 || d.frame < m.drawn[size_t(oldest)].frame)) oldest = i;
  }
  if (oldest >= 0) redraw[size_t(oldest)] = true;
  bool first = true;
  const bool any_redrawn = std::find(redraw.begin(), redraw.end(), true) != redraw.end();
  for (int i = 0; i < set_count; ++i) {
    if (!redraw[size_t(i)]) {
      skipped.push_back("specular impostors " + std::to_string(i) + ": drawn " +
                        std::to_string(m.frame - m.drawn[size_t(i)].frame) + " frame(s) ago (refresh period " +
                        std::to_string(level.refresh_period) + ")");
      continue;
    }
    m.add_impostors(graph, sets[size_t(i)], i, glm::ivec2(0, int(2 * face) * i), face, first);
    first = false;
    m.drawn[size_t(i)] = {m.frame, sets[size_t(i)].centre, sets[size_t(i)].objects, face, sg.revision()};
  }
  bool refractive = false, reflective = false;
  for (const ObjectInView& v : in_view) {
    refractive = refractive || v.refractive;
    reflective = reflective || v.reflective;
  }
  m.glass_in_view = refractive;
  m.glass_reflection_fresnel = level.glass_reflection_fresnel;
  m.mirrors_in_view = reflective;
  if (refractive) m.add_back_faces(graph, in_view, m.region);
  else skipped.push_back("specular back faces: no refractive object in view");

  bool caustics = false;
  if (m.caustics && level.caustic_map > 0) {
    std::vector<size_t>& objects = m.objects;
    objects.clear();
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const ObjectInView& v : in_view) {
      objects.push_back(v.object);
      lo = glm::min(lo, v.lo);
      hi = glm::max(hi, v.hi);
    }
    caustics = m.caustics->trace(graph, {m.constants, m.impostor_position, m.impostor_normal, m.impostor_albedo},
                                  lighting.lights, objects, 0.5f * (lo + hi), 0.5f * glm::length(hi - lo),
                                  level.caustic_map,
                                  {level.caustic_refresh_period, any_redrawn, sg.revision(), level.glass_reflection_stride,
                                   level.caustic_receiver_map},
                                  skipped);
  } else {
    skipped.push_back(m.caustics ? "specular caustics: off at this level" : "specular caustics: off (ablation)");
  }
  c->flags.w = caustics ? 1 : 0;
  m.caustics_recorded = caustics;
  if (caustics) {
    m.photons = m.caustics->photons();  // with the receiver maps, if the level has them
    if (!level.caustic_vpls) {
      m.photons.lamps.clear();
      skipped.push_back("specular caustic VPLs: off at this level (the technique gets no photons)");
    }
  }
  m.active = true;
  return ok_status();
}

Status SpecularStage::finish(const shading::DirectLightOutput* direct, std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  if (!m.active) return ok_status();
  gpu::FrameGraph& graph = *m.shared.graph;
  const light::Lighting& lighting = m.shared.light_stage->lighting();
  auto* c = static_cast<shader::SpecularConstants*>(graph.mapped(m.constants, graph.slot()));
  gpu::BufferHandle light_set = m.own_lights;
  gpu::ImageHandle shadow_primary = m.no_shadow, shadow_virtual = m.no_shadow;
  if (direct) {
    light_set = direct->light_set;
    shadow_primary = direct->shadow_primary;
    shadow_virtual = direct->shadow_virtual;
    c->shadow = direct->shadow;
  } else {
    auto* set = static_cast<shader::LightSet*>(graph.mapped(m.own_lights, graph.slot()));
    light::write_unshadowed_light_set(lighting, *set);
    c->shadow = glm::vec4(1.0f, 1.0f, 1.0f, 0.0f);
    skipped.push_back("specular: the technique drew no shadow maps this frame: mirrors and glass show lamps' light unshadowed");
  }
  c->flags.x = direct ? 1 : 0;
  const bool caustics = m.caustics_recorded;
  const gpu::ImageHandle caustic_buffer = m.caustics ? m.caustics->buffer() : m.no_caustics;
  const VkSampler compare = m.shared.context->samplers().shadow_compare;
  const VkSampler nearest = m.shared.context->samplers().nearest_clamp;
  const glm::ivec4 region = m.region;
  Impl* self = &m;
  // The caustics on the diffuse pixels (into lit_rv) and in the caustic buffer the trace reads,
  // unless the technique's shading added the receiver maps (then the trace reads those).
  const bool receivers = caustics && m.photons.receivers.valid() && direct && direct->caustics_added;
  if (caustics && !receivers) m.caustics->splat(graph);
  c->flags.w = !caustics ? 0 : receivers ? 2 : 1;
  const gpu::ImageHandle receiver_maps = receivers ? m.photons.receivers : m.no_receivers;
  const gpu::BufferHandle receiver_lamps = receivers ? m.photons.receiver_lamps : m.no_receiver_lamps;
  // The specular pixels listed by kind, then a pass per kind in view over its list.
  const gpu::BufferHandle args = m.trace_args, counts = m.trace_counts, pixels = m.trace_pixels;
  graph.add_pass("specular trace list reset", gpu::PassKind::Transfer,
                 [args, counts](gpu::PassBuilder& b) {
                   b.write(args, gpu::Access::TransferDst);
                   b.write(counts, gpu::Access::TransferDst);
                 },
                 [args, counts](VkCommandBuffer cmd, gpu::PassContext& p) {
                   // (0, 1, 1, -) per list, by disjoint fills (overlapping ones in one pass are a
                   // write-after-write hazard).
                   const VkBuffer a = p.buffer(args);
                   vkCmdFillBuffer(cmd, a, 0, 4, 0u);
                   for (VkDeviceSize l = 0; l < kTraceLists; ++l) {
                     vkCmdFillBuffer(cmd, a, 16 * l + 4, 8, 1u);
                     vkCmdFillBuffer(cmd, a, 16 * l + 12, l + 1 < kTraceLists ? 8 : 4, 0u);
                   }
                   vkCmdFillBuffer(cmd, p.buffer(counts), 0, 16, 0u);
                 });
  const glm::ivec4 list_push[2] = {region, glm::ivec4(int(m.list_capacity), 0, 0, 0)};
  graph.add_shader_pass(
      "specular trace list", gpu::PassKind::Compute, *m.list_pipeline,
      [self, args, counts, pixels](gpu::ShaderPassBuilder& b) {
        b.bind("virtual_position", self->shared.virtual_position);
        b.bind("virtual_normal", self->shared.virtual_normal);
        b.bind("FrameUbo", self->shared.frame_constants);
        b.bind("SpecularUbo", self->constants);
        b.bind("Materials", self->shared.scene_gpu->materials);
        b.bind_over("TraceArgs", args);
        b.bind_over("TraceCounts", counts);
        b.bind("TracePixels", pixels);
      },
      [self, list_push, region](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *self->list_pipeline, list_push, sizeof list_push,
                               {(uint32_t(region.z) + 7) / 8, (uint32_t(region.w) + 7) / 8, 1});
      });
  for (int li = 0; li < kTraceLists; ++li) {
    if (!(kTraceList[li].refractive ? m.glass_in_view : m.mirrors_in_view)) continue;
    // A level that traces every glass reflection lists no glass pixel without one.
    if (kTraceList[li].refractive && !kTraceList[li].reflect && !(m.glass_reflection_fresnel > 0.0f)) continue;
    const gpu::Pipeline* pipe = &*m.trace_pipelines[li];
    const glm::ivec4 list(li * int(m.list_capacity), li, 0, 0);
    const VkDeviceSize offset = VkDeviceSize(16 * li);
    graph.add_shader_pass(
        kTraceList[li].pass, gpu::PassKind::Compute, *pipe,
        [=](gpu::ShaderPassBuilder& b) {
          const frame::FrameResources& r = self->shared;
          b.bind("FrameUbo", r.frame_constants);
          b.bind("LightUbo", light_set);
          b.bind("SpecularUbo", self->constants);
          b.bind("Materials", r.scene_gpu->materials);
          b.bind("real_position", r.real_position);
          b.bind("virtual_position", r.virtual_position);
          b.bind("virtual_normal", r.virtual_normal);
          b.bind("virtual_albedo", r.virtual_albedo);
          b.bind("back_position", self->back_position);
          b.bind("back_normal", self->back_normal);
          b.bind("impostor_position", self->impostor_position);
          b.bind("impostor_normal", self->impostor_normal);
          b.bind("impostor_albedo", self->impostor_albedo);
          b.bind_sampled("shadow_primary", shadow_primary, compare);
          b.bind_sampled("shadow_virtual", shadow_virtual, compare);
          b.bind_sampled("shadow_primary_depth", shadow_primary, nearest);
          b.bind_sampled("shadow_virtual_depth", shadow_virtual, nearest);
          b.bind("color_words", r.color_upload);
          b.bind("EnvGrid", self->env_grid);
          b.bind("caustics", caustic_buffer);
          b.bind("caustic_receivers", receiver_maps);
          b.bind("CausticReceiverLamps", receiver_lamps);
          b.bind("TraceCounts", counts);
          b.bind("TracePixels", pixels);
          b.uses().read(args, gpu::Access::IndirectRead);
          b.bind_over("lit_rv", r.lit_rv);
          b.bind_over("lit_r", r.lit_r);
        },
        [pipe, list, args, offset](VkCommandBuffer cmd, gpu::PassContext& p) {
          gpu::dispatch_indirect(cmd, *pipe, &list, sizeof list, p.buffer(args), offset);
        });
  }
  return ok_status();
}

bool SpecularStage::lights_outside_tiles() const { return impl_->caustics_recorded; }

const frame::CausticPhotons* SpecularStage::caustic_photons() const {
  const frame::CausticPhotons& p = impl_->photons;
  return p.lamps.empty() && !p.receivers.valid() ? nullptr : &p;
}

}  // namespace mrgi::specular
