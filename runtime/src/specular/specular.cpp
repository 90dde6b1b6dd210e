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
#include "specular/specular_internal.h"
#include "specular/specular_params.glsl"
#include "light/light_set_writer.h"
#include "frame/scene_gpu.h"
#include "frame/screen_bounds.h"

namespace mrgi::specular {
namespace {

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

}  // namespace

using specular_detail::ImpostorSet;
using specular_detail::kTraceList;
using specular_detail::kTraceLists;
using specular_detail::ObjectInView;

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

// The real grid's triangles of each face, seen from this set's centre.
void SpecularStage::Impl::add_impostor_cells(gpu::FrameGraph& graph, const ImpostorSet& set, const std::string& id,
                                             gpu::BufferHandle indices, gpu::BufferHandle draws) {
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

// Clears and begins rendering into the set's block of the atlas (its 3 x 2 faces at `origin`).
void SpecularStage::Impl::begin_impostor_rendering(VkCommandBuffer cmd, gpu::PassContext& p, const glm::ivec2& origin,
                                                   uint32_t face, gpu::Access depth_access) const {
  const gpu::Context& ctx = p.context();
  VkRenderingAttachmentInfo colour[3];
  const gpu::ImageHandle targets[3] = {impostor_position, impostor_normal, impostor_albedo};
  for (int i = 0; i < 3; ++i) {
    colour[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    colour[i].imageView = p.view(targets[i]);
    colour[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    colour[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // the render area: this set's block
    colour[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    colour[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  }
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = p.view(impostor_depth);
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
}

void SpecularStage::Impl::add_impostors(gpu::FrameGraph& graph, const ImpostorSet& set, int index,
                                        const glm::ivec2& origin, uint32_t face, bool first) {
  const frame::SceneGpu* sg = shared.scene_gpu;
  const std::string id = std::to_string(index);
  const bool grid = grid_points.width > 1 && grid_points.height > 1 &&
                    uint64_t(grid_points.width - 1) * (grid_points.height - 1) * 6 <= face_capacity;
  const gpu::BufferHandle indices = face_indices[size_t(index)], draws = face_draws[size_t(index)];
  if (grid) add_impostor_cells(graph, set, id, indices, draws);
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
        self->begin_impostor_rendering(cmd, p, origin, face, depth_access);
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

// The specular objects in view, in the scene's order: their boxes in the world and in this
// frame's camera, and their distances from it.
void SpecularStage::Impl::find_objects_in_view(const frame::SceneGpu& sg, const shader::FrameConstants& fc) {
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
}

// The objects' projected boxes (all of the image when a corner is behind the camera): the
// trace's dispatch, and the part of the back faces' buffers drawn and read. First pixel, size.
glm::ivec4 SpecularStage::Impl::trace_region(const shader::FrameConstants& fc) const {
  glm::vec2 lo_px(1e30f), hi_px(-1e30f);
  bool behind = false;
  for (const ObjectInView& v : in_view) {
    const frame::ScreenBounds& b = v.screen;
    behind = behind || b.behind;
    lo_px = glm::min(lo_px, b.min);
    hi_px = glm::max(hi_px, b.max);
  }
  const glm::ivec2 size(fc.internal_output_size.x, fc.internal_output_size.y);
  glm::ivec2 r0(0), r1 = size;
  if (!behind) {
    r0 = glm::clamp(glm::ivec2(glm::floor(lo_px)) - 1, glm::ivec2(0), size);
    r1 = glm::clamp(glm::ivec2(glm::ceil(hi_px)) + 2, glm::ivec2(0), size);
  }
  return glm::ivec4(r0, glm::max(r1 - r0, glm::ivec2(0)));
}

// The objects in view (nearest first) into `set_count` sets: one each, the rest in the last;
// each set centred on its objects' box.
void SpecularStage::Impl::group_into_sets(int set_count) {
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
}

// This frame's constants but for flags.x (finish()) and flags.w (the caustics). `size`: the
// internal frame's.
void SpecularStage::Impl::write_constants(shader::SpecularConstants& c, const SpecularLevel& level, uint32_t face,
                                          int set_count, const glm::ivec2& size) {
  c = shader::SpecularConstants{};
  c.counts = glm::ivec4(set_count, level.search_steps, level.refine_steps, level.back_face_steps);
  c.params = glm::vec4(settings.depth_tolerance, shared.compose_eps, shared.compose_alpha_max,
                       settings.back_projection ? 1.0f : 0.0f);
  for (int i = 0; i < set_count; ++i) {
    c.sets[i].centre = glm::vec4(sets[size_t(i)].centre, sets[size_t(i)].radius);
    c.sets[i].atlas = glm::ivec4(0, int(2 * face) * i, int(face), 0);
  }
  const int grid_width = write_environment(c);
  c.flags = glm::ivec4(0, settings.depth_test ? 1 : 0, grid_width, 0);  // x: finish()
  c.level = glm::vec4(float(std::max(level.glass_reflection_stride, 1)), level.glass_reflection_fresnel, 0.0f, 0.0f);
  // Where add_back_faces draws (its render area; all of the frame for an empty box).
  c.back_rect = region.z > 0 && region.w > 0
                    ? glm::ivec4(region.x, region.y, region.x + region.z, region.y + region.w)
                    : glm::ivec4(0, 0, size.x, size.y);
}

// L_env: the SH of the ambient and the foldable lamps into `c`, and the environment grid's
// cells into env_grid when the light stage has one of the allocated width. Returns the width
// written (0: none, the trace takes the SH).
int SpecularStage::Impl::write_environment(shader::SpecularConstants& c) {
  gpu::FrameGraph& graph = *shared.graph;
  const light::Lighting& lighting = shared.light_stage->lighting();
  for (int k = 0; k < 16; ++k) {
    glm::dvec3 e = lighting.ambient_real[size_t(k)] + lighting.ambient_virtual[size_t(k)];
    for (size_t l = 0; l < lighting.lights.size(); ++l)
      if (l < lighting.foldable.size() && lighting.foldable[l] != 0 && l < lighting.light_sh.size())
        e += lighting.light_sh[l][size_t(k)];
    c.env_sh[k] = glm::vec4(glm::vec3(e), 0.0f);
  }
  int grid_width = 0;
  if (const light::EnvSampler* env = shared.light_stage->environment_grid();
      env && env->settings().grid_width == env_width) {
    grid_width = env_width;
    auto* cells = static_cast<glm::vec4*>(graph.mapped(env_grid, graph.slot()));
    for (int y = 0; y < env->grid_height(); ++y)
      for (int x = 0; x < grid_width; ++x) cells[size_t(y) * size_t(grid_width) + size_t(x)] = glm::vec4(glm::vec3(env->cell_radiance(x, y)), 0.0f);
  }
  return grid_width;
}

// Redraw the sets whose content changed; of the rest, the oldest one if it is refresh_period
// frames old (at most one stale set is refreshed a frame: the fast level spreads the sets over
// frames).
void SpecularStage::Impl::choose_redraws(const frame::SceneGpu& sg, const SpecularLevel& level, uint32_t face,
                                         int set_count) {
  redraw.assign(size_t(set_count), false);
  int oldest = -1;
  for (int i = 0; i < set_count; ++i) {
    const Impl::DrawnSet& d = drawn[size_t(i)];
    const ImpostorSet& s = sets[size_t(i)];
    const bool changed = d.objects != s.objects || d.face != face || d.revision != sg.revision() ||
                         glm::any(glm::greaterThan(glm::abs(d.centre - s.centre), glm::vec3(1e-5f)));
    if (changed || level.refresh_period <= 1) redraw[size_t(i)] = true;
    else if (frame - d.frame >= level.refresh_period && (oldest < 0 || d.frame < drawn[size_t(oldest)].frame)) oldest = i;
  }
  if (oldest >= 0) redraw[size_t(oldest)] = true;
}

// The impostors of the sets due this frame (choose_redraws). Returns whether any was drawn.
bool SpecularStage::Impl::draw_impostor_sets(const frame::SceneGpu& sg, const SpecularLevel& level, uint32_t face,
                                             std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared.graph;
  const int set_count = int(sets.size());
  drawn.resize(size_t(settings.max_sets));
  ++frame;
  choose_redraws(sg, level, face, set_count);
  bool first = true;
  const bool any_redrawn = std::find(redraw.begin(), redraw.end(), true) != redraw.end();
  for (int i = 0; i < set_count; ++i) {
    if (!redraw[size_t(i)]) {
      skipped.push_back("specular impostors " + std::to_string(i) + ": drawn " +
                        std::to_string(frame - drawn[size_t(i)].frame) + " frame(s) ago (refresh period " +
                        std::to_string(level.refresh_period) + ")");
      continue;
    }
    add_impostors(graph, sets[size_t(i)], i, glm::ivec2(0, int(2 * face) * i), face, first);
    first = false;
    drawn[size_t(i)] = {frame, sets[size_t(i)].centre, sets[size_t(i)].objects, face, sg.revision()};
  }
  return any_redrawn;
}

// The photon passes of the level's caustics around the objects in view (Caustics::trace).
// Returns whether this frame has caustics.
bool SpecularStage::Impl::add_caustics(const frame::SceneGpu& sg, const SpecularLevel& level, bool any_redrawn,
                                       std::vector<std::string>& skipped) {
  if (!caustics || level.caustic_map == 0) {
    skipped.push_back(caustics ? "specular caustics: off at this level" : "specular caustics: off (ablation)");
    return false;
  }
  gpu::FrameGraph& graph = *shared.graph;
  const light::Lighting& lighting = shared.light_stage->lighting();
  objects.clear();
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const ObjectInView& v : in_view) {
    objects.push_back(v.object);
    lo = glm::min(lo, v.lo);
    hi = glm::max(hi, v.hi);
  }
  return caustics->trace(graph, {constants, impostor_position, impostor_normal, impostor_albedo},
                         lighting.lights, objects, 0.5f * (lo + hi), 0.5f * glm::length(hi - lo),
                         level.caustic_map,
                         {level.caustic_refresh_period, any_redrawn, sg.revision(), level.glass_reflection_stride,
                          level.caustic_receiver_map},
                         skipped);
}

Status SpecularStage::prepare(const shader::FrameConstants& fc, int technique_level, int technique_levels,
                              std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  m.active = false;
  m.photons = frame::CausticPhotons{};
  const frame::SceneGpu& sg = *m.shared.scene_gpu;
  gpu::FrameGraph& graph = *m.shared.graph;
  m.find_objects_in_view(sg, fc);
  std::vector<ObjectInView>& in_view = m.in_view;
  m.caustics_recorded = false;
  if (in_view.empty()) {
    skipped.push_back("specular: no reflective or refractive object in view");
    return ok_status();
  }
  m.region = m.trace_region(fc);
  std::sort(in_view.begin(), in_view.end(), [](const ObjectInView& a, const ObjectInView& b) { return a.distance < b.distance; });
  const SpecularLevel& level = specular_level_for(technique_level, technique_levels);
  const uint32_t face = std::min(level.impostor_face, m.settings.max_impostor_face);
  const int set_count = std::clamp(std::min(level.own_sets, m.settings.max_sets), 1, int(in_view.size()));
  m.group_into_sets(set_count);

  // This frame's constants.
  auto* c = static_cast<shader::SpecularConstants*>(graph.mapped(m.constants, graph.slot()));
  m.write_constants(*c, level, face, set_count, glm::ivec2(fc.internal_output_size.x, fc.internal_output_size.y));

  m.world_to_clip = fc.world_to_clip;
  m.camera_world = glm::vec3(fc.camera_world);
  m.internal_focal_px = fc.internal_k.x;
  m.set_grid(graph, face);
  const bool any_redrawn = m.draw_impostor_sets(sg, level, face, skipped);
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

  const bool caustics = m.add_caustics(sg, level, any_redrawn, skipped);
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

// The lights and shadow maps the trace reads: the technique's direct-light block's, or the stage's own lights
// unshadowed where it drew no shadow maps this frame. Sets c.shadow.
SpecularStage::Impl::TraceInputs SpecularStage::Impl::trace_light(
    const shading::DirectLightOutput* direct, shader::SpecularConstants& c,
    std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared.graph;
  const light::Lighting& lighting = shared.light_stage->lighting();
  TraceInputs in;
  in.light_set = own_lights;
  in.shadow_primary = no_shadow;
  in.shadow_virtual = no_shadow;
  if (direct) {
    in.light_set = direct->light_set;
    in.shadow_primary = direct->shadow_primary;
    in.shadow_virtual = direct->shadow_virtual;
    c.shadow = direct->shadow;
  } else {
    auto* set = static_cast<shader::LightSet*>(graph.mapped(own_lights, graph.slot()));
    light::write_unshadowed_light_set(lighting, *set);
    c.shadow = glm::vec4(1.0f, 1.0f, 1.0f, 0.0f);
    skipped.push_back("specular: the technique drew no shadow maps this frame: mirrors and glass show lamps' light unshadowed");
  }
  return in;
}

// The specular pixels listed by kind (trace_list.comp), after resetting the lists.
void SpecularStage::Impl::add_trace_list_passes() {
  gpu::FrameGraph& graph = *shared.graph;
  const Impl* self = this;
  const gpu::BufferHandle args = trace_args, counts = trace_counts, pixels = trace_pixels;
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
  const glm::ivec4 list_region = region;
  const glm::ivec4 list_push[2] = {list_region, glm::ivec4(int(list_capacity), 0, 0, 0)};
  graph.add_shader_pass(
      "specular trace list", gpu::PassKind::Compute, *list_pipeline,
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
      [self, list_push, list_region](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *self->list_pipeline, list_push, sizeof list_push,
                               {(uint32_t(list_region.z) + 7) / 8, (uint32_t(list_region.w) + 7) / 8, 1});
      });
}

// trace.comp over list `li` of kTraceList (its pixels, by the indirect arguments the list pass
// wrote), into lit_rv and lit_r.
void SpecularStage::Impl::add_trace_pass(int li, const TraceInputs& in) {
  gpu::FrameGraph& graph = *shared.graph;
  const Impl* self = this;
  const gpu::BufferHandle args = trace_args, counts = trace_counts, pixels = trace_pixels;
  const gpu::Pipeline* pipe = &*trace_pipelines[li];
  const glm::ivec4 list(li * int(list_capacity), li, 0, 0);
  const VkDeviceSize offset = VkDeviceSize(16 * li);
  graph.add_shader_pass(
      kTraceList[li].pass, gpu::PassKind::Compute, *pipe,
      [=](gpu::ShaderPassBuilder& b) {
        const frame::FrameResources& r = self->shared;
        b.bind("FrameUbo", r.frame_constants);
        b.bind("LightUbo", in.light_set);
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
        b.bind_sampled("shadow_primary", in.shadow_primary, in.compare);
        b.bind_sampled("shadow_virtual", in.shadow_virtual, in.compare);
        b.bind_sampled("shadow_primary_depth", in.shadow_primary, in.nearest);
        b.bind_sampled("shadow_virtual_depth", in.shadow_virtual, in.nearest);
        b.bind("color_words", r.color_upload);
        b.bind("EnvGrid", self->env_grid);
        b.bind("caustics", in.caustic_buffer);
        b.bind("caustic_receivers", in.receiver_maps);
        b.bind("CausticReceiverLamps", in.receiver_lamps);
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

Status SpecularStage::finish(const shading::DirectLightOutput* direct, std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  if (!m.active) return ok_status();
  gpu::FrameGraph& graph = *m.shared.graph;
  auto* c = static_cast<shader::SpecularConstants*>(graph.mapped(m.constants, graph.slot()));
  Impl::TraceInputs in = m.trace_light(direct, *c, skipped);
  c->flags.x = direct ? 1 : 0;
  const bool caustics = m.caustics_recorded;
  in.caustic_buffer = m.caustics ? m.caustics->buffer() : m.no_caustics;
  in.compare = m.shared.context->samplers().shadow_compare;
  in.nearest = m.shared.context->samplers().nearest_clamp;
  // The caustics on the diffuse pixels (into lit_rv) and in the caustic buffer the trace reads,
  // unless the technique's shading added the receiver maps (then the trace reads those).
  const bool receivers = caustics && m.photons.receivers.valid() && direct && direct->caustics_added;
  if (caustics && !receivers) m.caustics->splat(graph);
  c->flags.w = !caustics ? 0 : receivers ? 2 : 1;
  in.receiver_maps = receivers ? m.photons.receivers : m.no_receivers;
  in.receiver_lamps = receivers ? m.photons.receiver_lamps : m.no_receiver_lamps;
  // The specular pixels listed by kind, then a pass per kind in view over its list.
  m.add_trace_list_passes();
  for (int li = 0; li < kTraceLists; ++li) {
    if (!(kTraceList[li].refractive ? m.glass_in_view : m.mirrors_in_view)) continue;
    // A level that traces every glass reflection lists no glass pixel without one.
    if (kTraceList[li].refractive && !kTraceList[li].reflect && !(m.glass_reflection_fresnel > 0.0f)) continue;
    m.add_trace_pass(li, in);
  }
  return ok_status();
}

bool SpecularStage::lights_outside_tiles() const { return impl_->caustics_recorded; }

const frame::CausticPhotons* SpecularStage::caustic_photons() const {
  const frame::CausticPhotons& p = impl_->photons;
  return p.lamps.empty() && !p.receivers.valid() ? nullptr : &p;
}

}  // namespace mrgi::specular
