#include "shading/direct_light.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>

#include "frame/image_views.h"
#include "frame/scene_gpu.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "gpu/vk_check.h"
#include "light/light_stage.h"
#include "shading/shade_dispatch.h"
#include "shading/shadow_plan.h"
#include "shared/occlusion_math.h"
#include "specular/caustic_receiver.glsl"

namespace mrgi::shading {
namespace {

constexpr uint32_t kTopShadowSize = 2048;
// Depth bias of the shadow rasterisation: constant in units of the depth format's resolution
// at the primitive's depth, slope in units per unit of depth slope (hardware slope scaling).
constexpr float kDepthBiasConstant = 16.0f;
constexpr float kDepthBiasSlope = 2.5f;
// Largest projected error (map texels) of the virtual meshes' level of detail in the shadow maps.
constexpr float kCasterErrorTexels = 0.5f;

struct GridPush {
  glm::mat4 view_proj;
  glm::ivec4 grid;
};
struct CasterGrid {
  VkExtent2D points{0, 0};  // grid points per row, column
  uint32_t stride = 1;      // G-buffer pixels between points
  uint32_t index_count() const {
    return points.width > 1 && points.height > 1 ? (points.width - 1) * (points.height - 1) * 6 : 0;
  }
};

// The real caster grid for a G-buffer and a shadow map: a cell covers about `cell_texels`
// shadow texels across the G-buffer's larger side (the map's resolution over the view's
// geometry; a finer grid adds vertices the map cannot resolve). At most one point a pixel.
CasterGrid caster_grid(VkExtent2D gbuffer, uint32_t shadow_size, double cell_texels) {
  const uint32_t side = std::max(gbuffer.width, gbuffer.height);
  const double cells = std::max(1.0, double(shadow_size) / std::max(1.0, cell_texels));
  CasterGrid g;
  g.stride = std::max<uint32_t>(1, uint32_t(std::ceil(double(side) / cells)));
  g.points = {(gbuffer.width - 1) / g.stride + 1, (gbuffer.height - 1) / g.stride + 1};
  return g;
}

// direct_light.comp's push constants: LevelConstants, VolumeConstants (volume indirect only) and
// the screen indirect's divisor (y), the environment occlusion's (z; 0 = none this frame).
struct ShadePush {
  glm::vec4 shadow;
  VolumeIndirect::Constants volume;
  glm::ivec4 indirect;
  glm::ivec4 rect;  // this dispatch's pixels [x0, x1) x [y0, y1)
};

// direct_light.comp's specialisation constants, in constant_id order: the indirect encoding
// (0 none, 1 ScreenIndirect, 2 VolumeIndirect), kOneShadowMap, kCausticReceivers,
// kVolumeDifference, kVolumeVirtual; kRealOnly (constant_id 6) for the pixels outside the
// objects' bounds.
struct ShadeVariant {
  uint32_t indirect = 0;
  bool difference = false, virtual_volume = false, caustics = false, real_only = false;
  uint32_t key() const {
    return indirect | (difference ? 4u : 0u) | (virtual_volume ? 8u : 0u) | (caustics ? 16u : 0u) |
           (real_only ? 32u : 0u);
  }
};  // (kEnvOcclusion, constant_id 5, is the block's: on whenever the scene has virtual objects)

ShadeVariant variant_of(const IndirectLight& indirect, bool caustics) {
  ShadeVariant v;
  v.caustics = caustics;
  if (std::holds_alternative<ScreenIndirect>(indirect)) v.indirect = 1;
  if (const auto* volume = std::get_if<VolumeIndirect>(&indirect)) {
    v.indirect = 2;
    v.difference = volume->real_term == VolumeIndirect::RealTerm::Difference;
    v.virtual_volume = volume->virtual_present;
  }
  return v;
}

}  // namespace

struct DirectLightBlock::Impl {
  frame::FrameResources frame_;
  DirectLightOptions options_;

  ShadowPlan plan_;
  Bounds bounds_;
  uint64_t planned_revision_ = ~uint64_t(0);
  uint64_t planned_objects_ = 0;  // frame::SceneGpu::revision the plan's bounds were taken at
  int planned_shadowed_ = -1;
  std::vector<LightDesc> drawn_;                   // the lights with shadow maps this frame
  light::ShRgb folded_real_{}, folded_virtual_{};  // SH of the estimated lights folded into ambient
  light::ShRgb ambient_rv_{};                      // this frame's ambient of L_rv (radiance SH)
  std::unique_ptr<EnvironmentOcclusion> occlusion_;  // null without virtual objects
  gpu::BufferHandle lights_;                       // shader::LightSet, one per frame slot
  gpu::ImageHandle shadow_primary_, shadow_virtual_;
  frame::ImageViews views_;
  std::vector<VkImageView> primary_layer_views_, virtual_layer_views_;
  gpu::PipelineHandle grid_pipeline_, mesh_pipeline_, caster_indices_pipeline_;
  std::map<uint32_t, gpu::PipelineHandle> shade_pipelines_;  // by ShadeVariant::key
  // This frame's caustic receiver maps (frame::FrameInfo::caustics), read by the shading;
  // stand-ins bound where there are none.
  bool caustics_ = false;
  gpu::ImageHandle receivers_, no_receivers_;
  gpu::BufferHandle receiver_lamps_, no_receiver_lamps_;
  gpu::ImageHandle no_volume_;    // bound for the volumes without a volume input
  gpu::ImageHandle no_indirect_;  // bound for the packed image without a screen input
  gpu::ImageHandle no_occlusion_; // bound for env_occlusion without virtual objects
  IndirectLight indirect_;        // this frame's
  bool recorded_ = true;          // record() ran since begin_frame() (true: no begin_frame yet)
  gpu::BufferHandle caster_indices_;  // this frame's real caster mesh (shadow_caster_indices.comp)
  bool real_caster_faces_ = false;    // some face of the plan draws the real casters
  VkImageLayout depth_write_layout_ = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  // This frame's level (set by record before the passes are added).
  uint32_t shadow_size_ = kTopShadowSize;
  int pcf_radius_ = 1;
  CasterGrid grid_;

  Status init();
  Status create_maps();
  Status create_pipelines();
  Status create_stand_ins();
  // Re-plans the shadow maps when the light stage's lights or the number of shadowed estimated
  // lights changed; writes this slot's lights.
  Status update_lights(int shadowed_estimated);
  void add_shadow_passes(std::vector<std::string>& skipped);
  // The environment occlusion pass of `ambient` at `level` with `lights`' bounce off the objects
  // (only that bounce where the ambient is the residual estimate), or left out.
  void record_occlusion(const EnvOcclusionLevel& level, const light::ShRgb& ambient, const std::vector<LightDesc>& lights,
                        std::vector<std::string>& skipped);
  // shade_direct: `general` over `virtual_area` (the whole image when not known), `real_only`
  // over the bands around it.
  void add_shade_pass(const gpu::Pipeline& general, const gpu::Pipeline& real_only,
                      const std::optional<VkRect2D>& virtual_area);
  void render_faces(VkCommandBuffer cmd, gpu::PassContext& pass, const std::vector<ShadowFace>& faces,
                    const std::vector<VkImageView>& layer_views);
  // direct_light.comp's LevelConstants::shadow at this frame's level.
  glm::vec4 shadow_constants() const {
    return glm::vec4(float(shadow_size_) / float(kTopShadowSize), float(shadow_size_), float(kTopShadowSize),
                     float(pcf_radius_));
  }
};

Status DirectLightBlock::Impl::init() {
  const frame::SceneGpu& sg = *frame_.scene_gpu;
  if (!frame_.light_stage) return fail(ErrorKind::Internal, "direct light: no light stage");
  if (!sg.virtual_objects.empty()) bounds_.add(sg.virtual_objects.bounds_min, sg.virtual_objects.bounds_max);
  if (!sg.real_proxies.empty()) bounds_.add(sg.real_proxies.bounds_min, sg.real_proxies.bounds_max);
  MRGI_TRY(create_maps());
  if (sg.may_have_objects()) {
    auto occlusion = EnvironmentOcclusion::create(frame_);
    if (!occlusion) return occlusion.error();
    occlusion_ = std::move(*occlusion);
  }
  MRGI_TRY(create_pipelines());
  return create_stand_ins();
}

Status DirectLightBlock::Impl::create_maps() {
  gpu::Context& ctx = *frame_.context;
  gpu::FrameGraph& graph = *frame_.graph;
  const frame::SceneGpu& sg = *frame_.scene_gpu;
  // Shadow map layers for the most lights the stage can give: its declared lamps as they are,
  // the rest as real directional lights (one layer in each map).
  const light::LightStage& stage = *frame_.light_stage;
  std::vector<LightDesc> largest = frame_.scene->lights;
  while (int(largest.size()) < stage.max_lights()) {
    LightDesc d;
    d.type = LightType::Directional;
    largest.push_back(d);
  }
  MRGI_TRY(plan_shadow_maps(largest, bounds_, frame_.scene->path + ": lights", plan_));
  const size_t primary_layers = plan_.primary.size();
  // Nothing virtual: no virtual-caster map is ever drawn (update_lights).
  const size_t virtual_layers = sg.may_have_objects() ? plan_.virtual_only.size() : 0;
  plan_.primary.reserve(primary_layers);
  plan_.virtual_only.reserve(plan_.virtual_only.size());
  drawn_.reserve(largest.size());

  auto lights = graph.create_buffer({"direct_light_lights", sizeof(shader::LightSet), gpu::MemoryUsage::Upload, true},
                                    VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!lights) return lights.error();
  lights_ = *lights;

  auto make_map = [&](const char* name, size_t layers) -> Expected<gpu::ImageHandle> {
    gpu::ImageDesc d;
    d.name = name;
    d.format = VK_FORMAT_D32_SFLOAT;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = d.height = kTopShadowSize;
    d.layers = uint32_t(std::max<size_t>(1, layers));
    d.array_view = true;  // sampler2DArrayShadow, whatever the lamp count
    return graph.create_image(d, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
  };
  auto primary = make_map("shadow_primary", primary_layers);
  if (!primary) return primary.error();
  shadow_primary_ = *primary;
  auto virt = make_map("shadow_virtual", virtual_layers);
  if (!virt) return virt.error();
  shadow_virtual_ = *virt;

  views_ = frame::ImageViews(ctx.device());
  // A view a layer, for rendering each map (the shading pass samples the image's array view).
  auto make_views = [&](gpu::ImageHandle h, size_t layers, std::vector<VkImageView>& per_layer) -> Status {
    const gpu::GpuImage& img = graph.gpu_image(h);
    for (size_t i = 0; i < layers; ++i) {
      auto v = views_.create(img, VK_IMAGE_VIEW_TYPE_2D, uint32_t(i), 1);
      if (!v) return v.error();
      per_layer.push_back(*v);
    }
    return ok_status();
  };
  MRGI_TRY(make_views(shadow_primary_, primary_layers, primary_layer_views_));
  MRGI_TRY(make_views(shadow_virtual_, virtual_layers, virtual_layer_views_));
  depth_write_layout_ =
      gpu::access_info(gpu::PassKind::Graphics, gpu::Access::DepthAttachmentWrite, true, true).layout;

  // Index buffer for the finest grid any level uses (one point a G-buffer pixel).
  const VkExtent2D gbuffer = graph.allocated_extent(frame_.real_position);
  const CasterGrid finest{gbuffer, 1};
  auto ib = graph.create_buffer({"shadow_caster_indices", std::max<VkDeviceSize>(4, VkDeviceSize(finest.index_count()) * 4)},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  if (!ib) return ib.error();
  caster_indices_ = *ib;
  return ok_status();
}

Status DirectLightBlock::Impl::create_pipelines() {
  gpu::Context& ctx = *frame_.context;
  auto grid_vs = gpu::shader_spirv("shading/shadow_depth_grid.vert");
  if (!grid_vs) return grid_vs.error();
  gpu::GraphicsPipelineDesc grid;
  grid.name = "direct_light_shadow_grid";
  grid.vertex_spirv = *grid_vs;
  grid.push_constant_bytes = sizeof(GridPush);
  grid.depth_format = VK_FORMAT_D32_SFLOAT;
  grid.cull_mode = VK_CULL_MODE_NONE;
  grid.depth_bias_constant = kDepthBiasConstant;
  grid.depth_bias_slope = kDepthBiasSlope;
  auto gp = gpu::create_graphics_pipeline(ctx, grid);
  if (!gp) return gp.error();
  grid_pipeline_ = gpu::PipelineHandle(ctx, std::move(*gp));
  MRGI_TRY(gpu::require_bindings(*grid_pipeline_, grid.name, {"real_position"}));

  auto cip = gpu::load_compute_pipeline(ctx, "shading/shadow_caster_indices.comp", {});
  if (!cip) return cip.error();
  caster_indices_pipeline_ = std::move(*cip);

  auto mesh_vs = gpu::shader_spirv("shading/shadow_mesh.vert");
  if (!mesh_vs) return mesh_vs.error();
  gpu::GraphicsPipelineDesc mesh;
  mesh.name = "direct_light_shadow_mesh";
  mesh.vertex_spirv = *mesh_vs;
  mesh.push_constant_bytes = sizeof(glm::mat4);
  mesh.vertex_strides = {sizeof(frame::GpuVertex)};
  mesh.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
  mesh.depth_format = VK_FORMAT_D32_SFLOAT;
  mesh.cull_mode = VK_CULL_MODE_NONE;
  mesh.depth_bias_constant = kDepthBiasConstant;
  mesh.depth_bias_slope = kDepthBiasSlope;
  auto mp = gpu::create_graphics_pipeline(ctx, mesh);
  if (!mp) return mp.error();
  mesh_pipeline_ = gpu::PipelineHandle(ctx, std::move(*mp));

  auto shade_spv = gpu::shader_spirv("shading/direct_light.comp");
  if (!shade_spv) return shade_spv.error();
  // One pipeline per variant a frame may ask for: the indirect encodings the options allow and,
  // with a reflective or refractive material in the scene, each also with kCausticReceivers (the
  // specular stage's fast level adds its caustics here).
  std::vector<ShadeVariant> variants{{}};
  if (options_.screen_indirect) variants.push_back({1, false, false, false});
  if (options_.volume_indirect)
    for (const bool difference : {false, true})
      for (const bool virtual_volume : {false, true}) variants.push_back({2, difference, virtual_volume, false});
  const bool specular = frame_.scene_gpu->specular;
  // Each also as kRealOnly, for the pixels no virtual object can cover.
  for (ShadeVariant v : variants) {
    for (const bool caustics : {false, true}) {
      if (caustics && !specular) continue;
      v.caustics = caustics;
      for (const bool real_only : {false, true}) {
        v.real_only = real_only;
        auto sp = gpu::create_compute_pipeline(
            ctx, {"direct_light_" + std::to_string(v.key()), *shade_spv, {}, sizeof(ShadePush),
                  {v.indirect, options_.one_shadow_map ? 1u : 0u, caustics ? 1u : 0u, v.difference ? 1u : 0u,
                   v.virtual_volume ? 1u : 0u, occlusion_ ? 1u : 0u, real_only ? 1u : 0u}});
        if (!sp) return sp.error();
        shade_pipelines_[v.key()] = gpu::PipelineHandle(ctx, std::move(*sp));
      }
    }
  }
  return ok_status();
}

Status DirectLightBlock::Impl::create_stand_ins() {
  gpu::FrameGraph& graph = *frame_.graph;
  auto no_receivers = graph.create_zero_image("direct_light_no_caustic_receivers", VK_FORMAT_R32G32B32A32_SFLOAT,
                                              VK_IMAGE_USAGE_STORAGE_BIT);
  if (!no_receivers) return no_receivers.error();
  no_receivers_ = *no_receivers;
  auto no_receiver_lamps = graph.create_buffer({"direct_light_no_caustic_receiver_lamps", sizeof(shader::CausticReceivers)},
                                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!no_receiver_lamps) return no_receiver_lamps.error();
  no_receiver_lamps_ = *no_receiver_lamps;
  auto no_volume = graph.create_zero_image("direct_light_no_volume", VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT, 2, 2, 2);
  if (!no_volume) return no_volume.error();
  no_volume_ = *no_volume;
  auto no_indirect = graph.create_zero_image("direct_light_no_indirect", VK_FORMAT_R32G32B32A32_UINT, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!no_indirect) return no_indirect.error();
  no_indirect_ = *no_indirect;
  auto no_occlusion = graph.create_zero_image("direct_light_no_env_occlusion", VK_FORMAT_R16G16B16A16_SFLOAT,
                                              VK_IMAGE_USAGE_STORAGE_BIT);
  if (!no_occlusion) return no_occlusion.error();
  no_occlusion_ = *no_occlusion;
  return ok_status();
}

Status DirectLightBlock::record(const frame::FrameInfo& info, const DirectLightLevel& level,
                                const IndirectLight& indirect, std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  m.recorded_ = true;
  const ShadeVariant variant = variant_of(indirect, false);
  if ((variant.indirect == 1 && !m.options_.screen_indirect) || (variant.indirect == 2 && !m.options_.volume_indirect))
    return fail(ErrorKind::BadUsage, std::string("direct light: a ") + (variant.indirect == 1 ? "screen" : "volume") +
                                         " indirect input, which DirectLightOptions did not declare");
  const EnvOcclusionLevel& occ = level.env_occlusion;
  if (occ.divisor < 1 || occ.divisor > 8 || occ.spheres_per_object < 0 ||
      occ.spheres_per_object > frame::SceneGpu::kOccluderSpheres || occ.regions < 0 ||
      occ.regions > MRGI_MAX_OCCLUSION_REGIONS || occ.near_field_steps < 0 || occ.near_field_steps > 64 ||
      !(occ.near_field_m >= 0.0f && occ.near_field_m <= 100.0f))
    return fail(ErrorKind::BadUsage, "direct light: env_occlusion divisor " + std::to_string(occ.divisor) +
                                         " (1..8), spheres " + std::to_string(occ.spheres_per_object) + " (0.." +
                                         std::to_string(frame::SceneGpu::kOccluderSpheres) + "), regions " +
                                         std::to_string(occ.regions) + " (0.." +
                                         std::to_string(MRGI_MAX_OCCLUSION_REGIONS) + "), near-field steps " +
                                         std::to_string(occ.near_field_steps) + " (0..64) or reach " +
                                         std::to_string(occ.near_field_m) + " m (0..100) out of range");
  m.shadow_size_ = level.shadow_map_size;
  m.pcf_radius_ = level.pcf_radius;
  m.indirect_ = indirect;
  gpu::FrameGraph& graph = *m.frame_.graph;
  m.grid_ = caster_grid(graph.extent(m.frame_.real_position), m.shadow_size_, level.caster_cell_shadow_texels);
  MRGI_TRY(m.update_lights(level.shadowed_estimated_lights));
  m.caustics_ = info.caustics && info.caustics->receivers.valid() && m.frame_.scene_gpu->specular;
  m.receivers_ = m.caustics_ ? info.caustics->receivers : m.no_receivers_;
  m.receiver_lamps_ = m.caustics_ ? info.caustics->receiver_lamps : m.no_receiver_lamps_;
  m.add_shadow_passes(skipped);
  m.record_occlusion(level.env_occlusion, m.ambient_rv_, m.drawn_, skipped);
  ShadeVariant v = variant_of(indirect, m.caustics_);
  const gpu::Pipeline& general = *m.shade_pipelines_.at(v.key());
  v.real_only = true;
  m.add_shade_pass(general, *m.shade_pipelines_.at(v.key()), info.virtual_area);
  return ok_status();
}

void DirectLightBlock::Impl::add_shadow_passes(std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *frame_.graph;
  if (plan_.primary.empty()) {
    skipped.push_back("shadow_primary: no lamp in the scene");
  } else {
    if (real_caster_faces_ && grid_.index_count() > 0) {
      graph.add_shader_pass(
          "shadow_caster_mesh", gpu::PassKind::Compute, *caster_indices_pipeline_,
          [this](gpu::ShaderPassBuilder& b) {
            b.bind_sampled("real_position", frame_.real_position, frame_.context->samplers().nearest_clamp);
            b.bind("Indices", caster_indices_);
          },
          [this](VkCommandBuffer cmd, gpu::PassContext&) {
            const glm::ivec4 g(int(grid_.points.width), int(grid_.points.height), int(grid_.stride), 0);
            gpu::dispatch_2d(cmd, *caster_indices_pipeline_, &g, sizeof(g), grid_.points.width - 1,
                             grid_.points.height - 1);
          });
    }
    graph.add_pass(
        "shadow_primary", gpu::PassKind::Graphics,
        [this](gpu::PassBuilder& b) {
          b.read(frame_.real_position, gpu::Access::Sampled);
          if (real_caster_faces_ && grid_.index_count() > 0) b.read(caster_indices_, gpu::Access::IndexBuffer);
          b.read(frame_.scene_gpu->real_proxies.vertices, gpu::Access::VertexBuffer);
          b.read(frame_.scene_gpu->real_proxies.indices, gpu::Access::IndexBuffer);
          b.read(frame_.scene_gpu->virtual_objects.vertices, gpu::Access::VertexBuffer);
          b.read(frame_.scene_gpu->virtual_objects.indices, gpu::Access::IndexBuffer);
          b.write(shadow_primary_, gpu::Access::DepthAttachmentWrite);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
          render_faces(cmd, pass, plan_.primary, primary_layer_views_);
        });
  }
  if (plan_.real_lamps == 0) {
    skipped.push_back("shadow_virtual_casters: no real lamp (virtual lamps use one map)");
  } else if (frame_.scene_gpu->virtual_objects.empty()) {
    skipped.push_back("shadow_virtual_casters: no virtual object in the scene");
  } else {
    graph.add_pass(
        "shadow_virtual_casters", gpu::PassKind::Graphics,
        [this](gpu::PassBuilder& b) {
          b.read(frame_.scene_gpu->virtual_objects.vertices, gpu::Access::VertexBuffer);
          b.read(frame_.scene_gpu->virtual_objects.indices, gpu::Access::IndexBuffer);
          b.write(shadow_virtual_, gpu::Access::DepthAttachmentWrite);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
          render_faces(cmd, pass, plan_.virtual_only, virtual_layer_views_);
        });
  }
}

void DirectLightBlock::Impl::add_shade_pass(const gpu::Pipeline& pipeline, const gpu::Pipeline& real_only,
                                            const std::optional<VkRect2D>& virtual_area) {
  const VkSampler compare = frame_.context->samplers().shadow_compare;
  const VkSampler linear = frame_.context->samplers().linear_clamp;
  const VkSampler nearest = frame_.context->samplers().nearest_clamp;
  frame_.graph->add_shader_pass(
      "shade_direct", gpu::PassKind::Compute, pipeline,
      [this, compare, linear, nearest](gpu::ShaderPassBuilder& b) {
        const auto* volume = std::get_if<VolumeIndirect>(&indirect_);
        const auto* screen = std::get_if<ScreenIndirect>(&indirect_);
        const char* real[3] = {"real_volume_r", "real_volume_g", "real_volume_b"};
        const char* subtract[3] = {"subtract_volume_r", "subtract_volume_g", "subtract_volume_b"};
        const char* virt[3] = {"virtual_volume_r", "virtual_volume_g", "virtual_volume_b"};
        const bool difference = volume && volume->real_term == VolumeIndirect::RealTerm::Difference;
        for (int c = 0; c < 3; ++c) {
          b.bind_sampled(real[c], volume ? volume->real[c] : no_volume_, linear);
          b.bind_sampled(subtract[c], difference ? volume->subtract[c] : no_volume_, linear);
          b.bind_sampled(virt[c], volume && volume->virtual_present ? volume->virtual_[c] : no_volume_, linear);
        }
        frame::bind_shading_gbuffers(b, frame_);
        b.bind("screen_indirect", screen ? screen->packed : no_indirect_);
        b.bind("LightUbo", lights_);
        b.bind_sampled("shadow_primary", shadow_primary_, compare);
        b.bind_sampled("shadow_virtual", shadow_virtual_, compare);
        b.bind_sampled("shadow_primary_depth", shadow_primary_, nearest);  // kOneShadowMap only
        b.bind_sampled("shadow_virtual_depth", shadow_virtual_, nearest);
        b.bind("env_occlusion", occlusion_ ? occlusion_->image() : no_occlusion_);
        b.bind("caustic_receivers", receivers_);
        b.bind("CausticReceiverLamps", receiver_lamps_);
      },
      [this, &pipeline, &real_only, virtual_area](VkCommandBuffer cmd, gpu::PassContext& pass) {
        ShadePush pc{};
        pc.shadow = shadow_constants();
        if (const auto* volume = std::get_if<VolumeIndirect>(&indirect_)) pc.volume = volume->constants;
        if (const auto* screen = std::get_if<ScreenIndirect>(&indirect_)) pc.indirect.y = screen->divisor;
        pc.indirect.z = occlusion_ ? occlusion_->divisor() : 0;
        const VkExtent2D e = pass.extent(frame_.lit_rv);
        for (const ShadeDispatch& d : shade_dispatches(e, virtual_area)) {
          pc.rect = d.rect;
          gpu::dispatch_2d(cmd, d.real_only ? real_only : pipeline, &pc, sizeof(pc), uint32_t(d.rect.z - d.rect.x),
                           uint32_t(d.rect.w - d.rect.y));
        }
      });
}

Status DirectLightBlock::Impl::update_lights(int shadowed_estimated) {
  const light::Lighting& lighting = frame_.light_stage->lighting();
  const frame::SceneGpu& sg = *frame_.scene_gpu;
  if (sg.revision() != planned_objects_) {
    // The virtual objects moved: the maps are fitted to the scene's bounds again.
    bounds_ = shading::Bounds{};
    if (!sg.virtual_objects.empty()) bounds_.add(sg.virtual_objects.bounds_min, sg.virtual_objects.bounds_max);
    if (!sg.real_proxies.empty()) bounds_.add(sg.real_proxies.bounds_min, sg.real_proxies.bounds_max);
    planned_objects_ = sg.revision();
    planned_revision_ = ~uint64_t(0);
  }
  if (lighting.revision != planned_revision_ || shadowed_estimated != planned_shadowed_) {
    // Declared lamps always get their maps; of the estimated lights (environment regions, the
    // probeless dominant light), strongest first, the level's number do, the rest light as SH.
    drawn_.clear();
    folded_real_ = folded_virtual_ = light::ShRgb{};
    int kept = 0;
    for (size_t i = 0; i < lighting.lights.size(); ++i) {
      const bool foldable = lighting.foldable[i] != 0;
      if (!foldable || kept < shadowed_estimated) {
        drawn_.push_back(lighting.lights[i]);
        kept += foldable ? 1 : 0;
        continue;
      }
      light::ShRgb& into = lighting.lights[i].real ? folded_real_ : folded_virtual_;
      for (int c = 0; c < light::kMaxShCoeffs; ++c) into[size_t(c)] += lighting.light_sh[i][size_t(c)];
    }
    MRGI_TRY(shading::plan_shadow_maps(drawn_, bounds_, "light stage lights", plan_));
    if (frame_.scene_gpu->virtual_objects.empty()) {
      // Nothing virtual casts: the virtual-caster maps would stay empty (all lit), so none is
      // made and the shader treats st_v as 1.
      plan_.virtual_only.clear();
      for (int i = 0; i < plan_.light_set.count.x; ++i) plan_.light_set.lights[i].layers.y = -1;
    }
    real_caster_faces_ = false;
    for (const shading::ShadowFace& f : plan_.primary) real_caster_faces_ = real_caster_faces_ || f.real_casters;
    planned_revision_ = lighting.revision;
    planned_shadowed_ = shadowed_estimated;
  }
  auto* set = static_cast<shader::LightSet*>(frame_.graph->mapped(lights_, frame_.graph->slot()));
  *set = plan_.light_set;
  set->count.y = lighting.ambient_is_residual ? 1 : 0;
  light::ShRgb real = lighting.ambient_real, both;
  for (int i = 0; i < light::kMaxShCoeffs; ++i) {
    real[size_t(i)] += folded_real_[size_t(i)];
    both[size_t(i)] = real[size_t(i)] + lighting.ambient_virtual[size_t(i)] + folded_virtual_[size_t(i)];
  }
  ambient_rv_ = both;
  const auto rv = light::irradiance_matrices(both);
  const auto r = light::irradiance_matrices(real);
  set->ambient_rv = {rv[0], rv[1], rv[2]};
  set->ambient_r = {r[0], r[1], r[2]};
  return ok_status();
}

void DirectLightBlock::Impl::render_faces(VkCommandBuffer cmd, gpu::PassContext& pass,
                            const std::vector<shading::ShadowFace>& faces,
                            const std::vector<VkImageView>& layer_views) {
  const gpu::Context& ctx = pass.context();
  const frame::SceneGpu& sg = *frame_.scene_gpu;
  const uint32_t grid_indices = grid_.index_count();
  const uint32_t s = shadow_size_;
  for (const shading::ShadowFace& face : faces) {
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = layer_views[size_t(face.layer)];
    depth.imageLayout = depth_write_layout_;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {1.0f, 0};
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {s, s}};
    ri.layerCount = 1;
    ri.pDepthAttachment = &depth;
    pass.context().fn().cmd_begin_rendering(cmd, &ri);
    const VkViewport vp{0.0f, 0.0f, float(s), float(s), 0.0f, 1.0f};
    const VkRect2D sc{{0, 0}, {s, s}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &sc);
    if (face.real_casters && grid_indices > 0) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, grid_pipeline_->pipeline);
      gpu::DescriptorPush()
          .sampled_image(grid_pipeline_->interface.find("real_position")->binding, pass.view(frame_.real_position),
                         ctx.samplers().nearest_clamp)
          .push(ctx, cmd, *grid_pipeline_);
      GridPush pc{face.view_proj, glm::ivec4(int(grid_.points.width), int(grid_.points.height), int(grid_.stride), 0)};
      vkCmdPushConstants(cmd, grid_pipeline_->layout, grid_pipeline_->stages, 0, sizeof(pc), &pc);
      vkCmdBindIndexBuffer(cmd, pass.buffer(caster_indices_), 0, VK_INDEX_TYPE_UINT32);
      vkCmdDrawIndexed(cmd, grid_indices, 1, 0, 0, 0);
    }
    const bool proxies = face.real_casters && !sg.real_proxies.empty();
    const bool virtuals = face.virtual_casters && !sg.virtual_objects.empty();
    if (proxies || virtuals) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mesh_pipeline_->pipeline);
      vkCmdPushConstants(cmd, mesh_pipeline_->layout, mesh_pipeline_->stages, 0, sizeof(glm::mat4),
                         &face.view_proj);
      if (proxies) sg.real_proxies.draw(cmd, pass, nullptr);
      if (virtuals) {
        // The coarsest level of detail within half a map texel: finer geometry the map cannot
        // hold (desk_spot's bunny at full detail into 256^2 maps: 2 ms of a 30 ms frame).
        frame::LodView lod = face.lod_per_texel;
        lod.focal_px *= float(s);
        lod.max_error_px = kCasterErrorTexels;
        sg.virtual_objects.draw(cmd, pass, nullptr, nullptr, lod.focal_px > 0.0f ? &lod : nullptr);
      }
    }
    pass.context().fn().cmd_end_rendering(cmd);
  }
}

void DirectLightBlock::Impl::record_occlusion(const EnvOcclusionLevel& level, const light::ShRgb& ambient,
                                              const std::vector<LightDesc>& lights, std::vector<std::string>& skipped) {
  if (!occlusion_) return;
  const light::Lighting& lighting = frame_.light_stage->lighting();
  // The residual estimate (lamps without an environment) is the room's own bounce as seen
  // through the camera; occluding it measured worse (corner, baseline high RDE 0.339 -> 0.349)
  // and changed no other lamp scene, so it stays unoccluded (the lamps' bounce off the objects
  // is still drawn).
  if (lighting.ambient_is_residual) skipped.push_back("env_occlusion: the ambient is the lamps' residual estimate, not occluded");
  occlusion_->record(level, ambient, lighting.ambient_regions, lights, !lighting.ambient_is_residual, skipped);
}

DirectLightBlock::EnvOcclusionResult DirectLightBlock::record_env_occlusion(const EnvOcclusionLevel& level,
                                                                            std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  if (!m.occlusion_) return {m.no_occlusion_, 0};
  const light::Lighting& lighting = m.frame_.light_stage->lighting();
  light::ShRgb ambient;
  for (size_t i = 0; i < ambient.size(); ++i) ambient[i] = lighting.ambient_real[i] + lighting.ambient_virtual[i];
  m.record_occlusion(level, ambient, lighting.lights, skipped);
  return {m.occlusion_->image(), m.occlusion_->divisor()};
}

void DirectLightBlock::begin_frame() { impl_->recorded_ = false; }

std::optional<DirectLightOutput> DirectLightBlock::output() const {
  const Impl& m = *impl_;
  if (!m.recorded_) return std::nullopt;
  return DirectLightOutput{m.lights_, m.shadow_primary_, m.shadow_virtual_, m.shadow_constants(), m.caustics_};
}

DirectLightBlock::DirectLightBlock(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DirectLightBlock::~DirectLightBlock() = default;

Expected<std::unique_ptr<DirectLightBlock>> DirectLightBlock::create(const frame::FrameResources& frame,
                                                                     const DirectLightOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->frame_ = frame;
  impl->options_ = options;
  MRGI_TRY(impl->init());
  return std::unique_ptr<DirectLightBlock>(new DirectLightBlock(std::move(impl)));
}

const std::array<DirectLightLevel, 4>& direct_light_levels() {
  static const std::array<DirectLightLevel, 4> levels = {{
      {2048, 1, 2.0, 4, {1, 16, 4, 12}},  // high
      {1024, 1, 2.0, 4, {2, 16, 4, 10}},  // medium
      {512, 1, 2.0, 2, {4, 8, 1, 8}},     // low
      {256, 0, 2.0, 1, {4, 4, 0, 6}},     // lowest
  }};
  return levels;
}

}  // namespace mrgi::shading
