#include "technique/dir/dir.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "common/vpl.glsl"
#include "gi/ism.h"
#include "gi/rsm.h"
#include "gi/vpl.h"
#include "gi/vpl_bounce.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "light/light_stage.h"
#include "gi/input_reuse.h"
#include "technique/knobs.h"
#include "technique/laddered.h"
#include "frame/scene_gpu.h"

namespace mrgi::technique {

const std::array<DirLevel, 5>& dir_levels() {
  static const std::array<DirLevel, 5> levels = {{
      {"paper", 256, 64, 16, 4, 128, 1024, 512, 4, 4, 1, 1.0f, 0.0f, -1, 0, true, 0.5f},
      {"high", 256, 64, 0, 1, 64, 512, 256, 4, 4, 1, 1.0f, 0.0f, -1, 0, false, 0.5f},
      {"medium", 64, 16, 0, 1, 64, 512, 256, 2, 4, 1, 1.0f, 0.0f, -1, 1, false, 0.5f},
      {"fast", 32, 0, 0, 1, 32, 256, 64, 1, 4, 2, 0.5f, 0.5f, 0, 3, false, 1.5f},
      {"fastest", 16, 0, 0, 1, 32, 128, 64, 1, 4, 2, 0.5f, 0.5f, 0, 3, false, 1.5f},
  }};
  return levels;
}

namespace {
const KnobField<DirLevel> kDirKnobs[] = {
    {"vpls", "virtual point lights", &DirLevel::vpls},
    {"bounce_vpls", "of them, the bounce light source's (0: one bounce)", &DirLevel::bounce_vpls},
    {"env_vpls", "of them, at most this many environment regions' (directional VPLs)", &DirLevel::env_vpls},
    {"env_parts", "VPLs each environment region is split into (at most interleave^2; interleaved)",
     &DirLevel::env_parts, true},
    {"ism_size", "texels per side of each VPL's imperfect shadow maps", &DirLevel::ism_size, true},
    {"points_per_vpl", "points splatted into each of a VPL's two maps", &DirLevel::points_per_vpl},
    {"rsm_size", "texels per side of each reflective shadow map", &DirLevel::rsm_size, true},
    {"rsm_lamps", "lamps, strongest first, whose maps spawn VPLs", &DirLevel::rsm_lamps},
    {"interleave", "side of the interleaved-sampling block (pixels)", &DirLevel::interleave},
    {"indirect_divisor", "G-buffer pixels per side of an indirect-light texel", &DirLevel::indirect_divisor, true},
    {"internal_scale", "fraction of the output width and height", &DirLevel::internal_scale},
    {"mesh_error_px", "largest projected error of the virtual meshes' level of detail (internal pixels)",
     &DirLevel::mesh_error_px},
    {"compose_tolerance",
     "8-bit levels a tile's composite may move a pixel by and the tile still keep the camera frame (rounding adds up to half a level)",
     &DirLevel::compose_tolerance},
    {"shadowed_env", "environment regions the direct-light block shadows with maps (-1: its level's)", &DirLevel::shadowed_env},
    {"baseline_level", "the direct-light block's level for the direct light", &DirLevel::baseline_level},
    {"real_bounce_beside_camera_ambient",
     "1: virtual pixels take the real-path VPLs' bounce also where the ambient's lower hemisphere is the colour "
     "camera's light (env camera); 0: the ambient's there",
     &DirLevel::real_bounce_beside_camera_ambient},
};
}  // namespace

// Environment VPLs allocated (the most any level places: regions times parts).
constexpr uint32_t kMaxEnvVpls = 64;

Expected<std::vector<DirLevel>> dir_levels(const std::vector<KnobSetting>& knobs) {
  auto levels = apply_knobs<DirLevel>("dir", dir_levels(), kDirKnobs, knobs);
  if (!levels) return levels;
  for (const DirLevel& l : *levels)
    if (l.bounce_vpls >= l.vpls)  // the lamps keep at least one slot
      return fail(ErrorKind::BadUsage, std::string("dir level ") + l.name + ": bounce_vpls " +
                                           std::to_string(l.bounce_vpls) + " must be below vpls " +
                                           std::to_string(l.vpls) + " (the lamps keep at least one VPL)");
  for (const DirLevel& l : *levels) {
    const uint32_t p = l.env_parts;
    if (p == 0 || p > std::max(1u, l.interleave * l.interleave) || p > kMaxEnvVpls)
      return fail(ErrorKind::BadUsage, std::string("dir level ") + l.name + ": env_parts " + std::to_string(p) +
                                           " must be at most interleave^2 (" +
                                           std::to_string(l.interleave * l.interleave) +
                                           "): each part shades one class of the interleaving block");
  }
  return levels;
}

Expected<std::vector<QualityLevel>> dir_ladder(const std::vector<KnobSetting>& knobs) {
  auto levels = dir_levels(knobs);
  if (!levels) return levels.error();
  return ladder_of(*levels, dir_levels(), kDirKnobs);
}

namespace {

// shaders/dir/dir_params.glsl DirParams.
struct DirPush {
  glm::ivec4 vpls;
  glm::vec4 lighting;
  glm::ivec4 extent;
};

// The sphere the maps are fitted to: twice the virtual objects' largest bounding-box edge across
// (at least 0.25 m), as dlpv's volume: where the bounce that differs between the solutions starts.
constexpr float kMinInfluenceSide = 0.25f;
// The ISM test: a point is lit when its distance is within bias of the map's (relative, and
// absolute in metres): the maps are sparse splats of a few hundred points, a texel spans degrees.
constexpr float kIsmBiasRelative = 0.05f, kIsmBiasMetres = 0.01f;
// Frames the bounce runs on still inputs before the VPLs are reused: each adds a bounce to the
// last (the light of the lamps' VPLs, then 2, 3, 4 bounces: a path tracer's depth 5).
constexpr int kBounceGenerations = 3;
// Temporal smoothing (shaders/dir/temporal.comp): the share of the history kept at full
// confidence (a time constant of about 1 / (1 - 0.8) = 5 frames, the flicker of a VPL set
// averaged over that many), and the relative luminance change where the confidence starts to
// fall (to 0 at twice it).
constexpr float kTemporalBlend = 0.8f, kTemporalChange = 0.5f;

// shaders/dir/temporal.comp Params.
struct TemporalPush {
  glm::mat4 previous_world_to_camera;
  glm::vec4 previous_camera;
  glm::ivec4 extent;
  glm::vec4 params;
};

class Dir final : public Laddered<DirLevel> {
 public:
  Dir(const frame::FrameResources& shared, std::vector<DirLevel> levels, const DirAblation& ablation)
      : Laddered("dir", ladder_of(levels, dir_levels(), kDirKnobs), std::move(levels)),
        shared_(shared), ablation_(ablation) {}
  Status init();
  Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) override;

 private:
  Status create_gi_blocks(uint32_t top_vpls, uint32_t top_ism, uint32_t top_rsm, uint32_t top_bounce);
  // The VPL buffer's slots this frame (the lamps' VPLs take the rest).
  struct VplSlots {
    uint32_t bounce = 0, env = 0;  // bounce VPLs, environment VPLs (regions x parts)
    // The light stage's regions (indices into environment_regions()) with environment VPLs,
    // `regions` of them: every region without a shadow map, strongest first; each drawn as
    // `parts` VPLs (DirLevel::env_parts).
    uint32_t regions = 0, parts = 1;
    std::array<uint32_t, kMaxEnvVpls> region{};
    bool env_override = false;     // the level's shadowed_env holds: the VPLs shadow the regions
  };
  VplSlots plan_vpl_slots(const DirLevel& level, int level_shadowed);
  Status make_vpls(const frame::FrameInfo& info, const DirLevel& level, const VplSlots& slots, float clamp_m, bool close,
                   std::vector<std::string>& skipped);
  Expected<shading::ScreenIndirect> record_vpl_light(const frame::FrameInfo& info, const DirLevel& level,
                                                     const VplSlots& slots, float clamp_m,
                                                     std::vector<std::string>& skipped);

  frame::FrameResources shared_;
  std::optional<gi::ReflectiveShadowMaps> rsm_;
  std::optional<gi::VplSampler> vpls_;
  std::optional<gi::ImperfectShadowMaps> ism_;
  std::optional<gi::VplBounce> bounce_;
  // What the VPL buffer and ISMs hold from the last frame that made them (the bounce reads them).
  struct Made {
    bool valid = false;
    uint32_t vpls = 0, ism_size = 0, tiles_per_row = 0;
  } made_;
  int bounce_generations_ = 0;  // frames the bounce ran on inputs within reuse tolerance
  gpu::BufferHandle env_vpls_;  // this frame's environment VPLs (upload, per frame slot)
  gpu::ImageHandle indirect_, rows_, merged_;  // RGBA32UI, shaders/gi/indirect_pack.glsl
  gpu::ImageHandle smoothed_[2];               // temporal smoothing, alternate frames (history)
  gpu::PipelineHandle shade_, merge_rows_, merge_columns_, temporal_;
  // What the last smoothed image was made from: valid, its level, which image, the pose.
  struct History {
    bool valid = false;
    int level = -1;
    int image = 0;
    glm::dmat4 camera_to_world{1.0};
    uint32_t width = 0, height = 0;  // the smoothed light's size
  } history_;
  DirAblation ablation_;  // TechniqueOptions::research
  // The lamps' direct light, with the merged VPL light as its screen input.
  std::unique_ptr<shading::DirectLightBlock> direct_;
  std::optional<shading::DirectLightOutput> direct_light() const override { return direct_->output(); }
  bool glossy_ = false;  // glossy VPLs: the scene has a glossy virtual material (frame::SceneGpu::glossy)
  // This frame's lamps with VPLs (light index, view); reserved at init (no allocation per frame).
  std::vector<std::pair<size_t, gi::RsmView>> planned_;
  gi::InputReuse reuse_;  // what the VPLs and ISMs in the buffers were made from
  // Whether the lamp's light reaches a virtual object: the bounding sphere of some mesh range.
  bool lamp_reaches_objects(const LightDesc& lamp) const {
    for (const frame::DrawRange& d : shared_.scene_gpu->virtual_objects.draws)
      if (gi::lamp_reaches_sphere(lamp, 0.5f * (d.bounds_min + d.bounds_max), 0.5f * glm::length(d.bounds_max - d.bounds_min)))
        return true;
    return false;
  }
  bool has_virtual_ = false;
  glm::vec3 centre_{0.0f};
  float radius_ = 1.0f;
  uint64_t sized_for_layout_ = ~uint64_t(0);  // the SceneGpu::layout_revision radius_ was set for
};

// The GI blocks sized for the top level: the map pairs, the VPL sampler, the ISMs and the
// bounce light source (none without virtual objects: nothing differs between the solutions).
Status Dir::create_gi_blocks(uint32_t top_vpls, uint32_t top_ism, uint32_t top_rsm, uint32_t top_bounce) {
  gpu::FrameGraph& graph = *shared_.graph;
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  const glm::vec3 size = sg.virtual_objects.bounds_max - sg.virtual_objects.bounds_min;
  centre_ = 0.5f * (sg.virtual_objects.bounds_max + sg.virtual_objects.bounds_min);
  const float side = std::max(kMinInfluenceSide, 2.0f * std::max({size.x, size.y, size.z}));
  radius_ = 0.5f * side * std::sqrt(3.0f);
  sized_for_layout_ = sg.layout_revision();
  gi::RsmSettings rs;
  rs.name = "dir rsm";
  rs.size = top_rsm;
  auto rsm = gi::ReflectiveShadowMaps::create(graph, sg, {shared_.real_position, shared_.real_normal, shared_.real_albedo}, rs);
  if (!rsm) return rsm.error();
  rsm_.emplace(std::move(*rsm));
  gi::VplSettings vs;
  vs.name = "dir vpl";
  vs.max_vpls = top_vpls;
  vs.map_size = top_rsm;
  vs.history = true;  // reused while nothing moved (gi::InputReuse)
  vs.glossy = sg.glossy;
  auto vpls = gi::VplSampler::create(graph, vs);
  if (!vpls) return vpls.error();
  vpls_.emplace(std::move(*vpls));
  gi::IsmSettings is;
  is.name = "dir ism";
  is.max_vpls = top_vpls;
  is.map_size = top_ism;
  is.history = true;
  auto ism = gi::ImperfectShadowMaps::create(graph, sg, shared_.real_position, shared_.real_normal, is);
  if (!ism) return ism.error();
  ism_.emplace(std::move(*ism));
  if (top_bounce > 0 && !ablation_.one_bounce) {
    gi::VplBounceSettings bs;
    bs.name = "dir bounce";
    bs.max_slots = top_bounce;
    bs.glossy = sg.glossy;
    auto bounce = gi::VplBounce::create(graph, sg, {shared_.real_position, shared_.real_normal, shared_.real_albedo}, bs);
    if (!bounce) return bounce.error();
    bounce_.emplace(std::move(*bounce));
  }
  return ok_status();
}

Status Dir::init() {
  gpu::FrameGraph& graph = *shared_.graph;
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (!shared_.light_stage) return fail(ErrorKind::Internal, "dir: no light stage");
  has_virtual_ = sg.may_have_objects();
  uint32_t top_vpls = 1, top_ism = 8, top_rsm = 16, top_lamps = 1, top_bounce = 0;
  for (const DirLevel& l : levels_) {
    top_vpls = std::max(top_vpls, l.vpls);
    top_bounce = std::max(top_bounce, l.bounce_vpls);
    top_ism = std::max(top_ism, l.ism_size);
    top_rsm = std::max(top_rsm, l.rsm_size);
    top_lamps = std::max(top_lamps, l.rsm_lamps);
  }
  planned_.reserve(top_lamps);
  if (has_virtual_) MRGI_TRY(create_gi_blocks(top_vpls, top_ism, top_rsm, top_bounce));
  gpu::BufferDesc ed{"dir environment vpls", VkDeviceSize(kMaxEnvVpls) * sizeof(shader::Vpl), gpu::MemoryUsage::Upload};
  auto env = graph.create_buffer(ed, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!env) return env.error();
  env_vpls_ = *env;
  auto image = [&](const char* name) {
    gpu::ImageDesc d;
    d.name = name;
    d.format = VK_FORMAT_R32G32B32A32_UINT;
    return graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
  };
  auto indirect = image("dir indirect");
  if (!indirect) return indirect.error();
  indirect_ = *indirect;
  auto rows = image("dir indirect rows");
  if (!rows) return rows.error();
  rows_ = *rows;
  auto merged = image("dir indirect merged");
  if (!merged) return merged.error();
  merged_ = *merged;
  for (int k = 0; k < 2; ++k) {
    gpu::ImageDesc d;
    d.name = k == 0 ? "dir indirect smoothed 0" : "dir indirect smoothed 1";
    d.format = VK_FORMAT_R32G32B32A32_UINT;
    d.history = true;  // read by the next frame
    auto h = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
    if (!h) return h.error();
    smoothed_[k] = *h;
  }
  // The shading pass with the ablations compiled in (shade_vpl.comp kAblation), the others plain.
  const DirAblation& ablation = ablation_;
  const uint32_t ablation_bits = (ablation.one_shadow_map ? 1u : 0u) | (ablation.no_real_only_vpls ? 2u : 0u);
  auto shade_spv = gpu::shader_spirv("dir/shade_vpl.comp");
  if (!shade_spv) return shade_spv.error();
  // Glossy VPLs (shade_vpl.comp kGlossy) only in a scene with a glossy virtual material
  // (frame::SceneGpu::glossy): the lobes cost every pixel every VPL, taken or not, on lavapipe.
  glossy_ = shared_.scene_gpu->glossy;
  auto shade = gpu::create_compute_pipeline(graph.context(), {"dir shade vpls", *shade_spv, {}, sizeof(DirPush),
                                                              {ablation_bits, glossy_ ? 1u : 0u}});
  if (!shade) return shade.error();
  shade_ = gpu::PipelineHandle(graph.context(), std::move(*shade));
  for (auto [shader, out] : {std::pair{"dir/merge_rows.comp", &merge_rows_}, std::pair{"dir/merge_columns.comp", &merge_columns_},
                             std::pair{"dir/temporal.comp", &temporal_}}) {
    auto p = gpu::load_compute_pipeline(graph.context(), shader, {});
    if (!p) return p.error();
    *out = std::move(*p);
  }
  reuse_.reserve(size_t(shared_.depth_intrinsics.width) * size_t(shared_.depth_intrinsics.height), shared_.depth_scale);
  shading::DirectLightOptions direct;
  direct.one_shadow_map = ablation_.one_shadow_map;
  direct.screen_indirect = true;
  auto block = shading::DirectLightBlock::create(shared_, direct);
  if (!block) return block.error();
  direct_ = std::move(*block);
  return ok_status();
}

Status Dir::record(const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  direct_->begin_frame();
  auto level_or = level_for(info);
  if (!level_or) return level_or.error();
  const DirLevel& level = **level_or;
  const light::Lighting& lighting = shared_.light_stage->lighting();
  if (!glossy_)
    skipped.push_back("dir glossy VPLs: no glossy virtual material (metallic > 0.1 or roughness < 0.7) in the scene; every VPL reflects diffusely");
  shading::DirectLightLevel direct = shading::direct_light_levels()[size_t(level.baseline_level)];
  planned_.clear();
  if (!has_virtual_) {
    skipped.push_back("dir VPLs: no virtual object in the scene (the bounce is the same in both solutions)");
    reuse_.forget();
    made_.valid = false;
    history_.valid = false;
    return direct_->record(info, direct, {}, skipped);
  }
  // The maps follow the objects. Their side (radius_) is set when the objects are (start-up, an
  // object added or removed: SceneGpu::layout_revision), not as they move: rigid motion keeps it.
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  centre_ = 0.5f * (sg.virtual_objects.bounds_max + sg.virtual_objects.bounds_min);
  if (sized_for_layout_ != sg.layout_revision()) {
    const glm::vec3 size = sg.virtual_objects.empty() ? glm::vec3(0.0f) : sg.virtual_objects.bounds_max - sg.virtual_objects.bounds_min;
    radius_ = 0.5f * std::max(kMinInfluenceSide, 2.0f * std::max({size.x, size.y, size.z})) * std::sqrt(3.0f);
    sized_for_layout_ = sg.layout_revision();
  }
  for (size_t i = 0; i < lighting.lights.size() && planned_.size() < level.rsm_lamps; ++i) {
    auto view = gi::rsm_view(lighting.lights[i], centre_, radius_, level.rsm_size);
    if (!view) {
      skipped.push_back("dir rsm (light " + std::to_string(i) + "): " + view.error().message);
      continue;
    }
    planned_.push_back({i, *view});
  }
  if (planned_.empty()) {
    skipped.push_back("dir VPLs: no light a map can see the virtual objects from");
    reuse_.forget();
    made_.valid = false;
    history_.valid = false;
    return direct_->record(info, direct, {}, skipped);
  }
  // The VPLs and ISMs in the buffers stand for this frame's while its inputs stay within
  // tolerance of the frame that made them (gi/input_reuse.h): no map, VPL or ISM pass.
  reuse_.set_frame(info.level, info.camera_to_world, info.camera, shared_.scene_gpu->revision());
  for (const auto& [i, view] : planned_) reuse_.add_lamp(lighting.lights[i]);
  const VplSlots slots = plan_vpl_slots(level, direct.shadowed_estimated_lights);
  if (slots.bounce == 0)
    skipped.push_back(level.bounce_vpls == 0 ? "dir bounce VPLs: none at this level (one bounce)"
                                             : "dir bounce VPLs: off (ablation one-bounce)");
  // A VPL stands for the light of the map's area over the VPL count, (2 radius)^2 / vpls: its
  // 1 / d^2 is clamped at that disk's radius.
  const float clamp_m = 2.0f * radius_ / std::sqrt(float(M_PI) * float(level.vpls));
  const bool close = reuse_.close();
  if (close && (slots.bounce == 0 || bounce_generations_ >= kBounceGenerations)) {
    skipped.push_back("dir maps, VPLs and ISMs: reused (level, pose, depth and lamps within tolerance of the frame that made them)");
  } else {
    MRGI_TRY(make_vpls(info, level, slots, clamp_m, close, skipped));
  }
  auto light = record_vpl_light(info, level, slots, clamp_m, skipped);
  if (!light) return light.error();
  // The environment regions the VPLs shadow are not also shadowed by maps.
  if (slots.env_override) direct.shadowed_estimated_lights = level.shadowed_env;
  // Environment VPLs (ISM-shadowed) carry the objects' occlusion of the environment: the block
  // then leaves it to them (with both, moving's real-pixel RDE at dir high went 0.44 -> 0.54).
  if (slots.env > 0) direct.env_occlusion.spheres_per_object = 0;
  // The VPLs carry the lamps' bounce off the objects: the block's occlusion leaves it out.
  direct.env_occlusion.lights_bounce = false;
  direct.env_occlusion.real_bounce_loss_lights = false;  // the lamps' VPLs in the objects' shadow are gone
  return direct_->record(info, direct, *light, skipped);
}

// The VPL buffer's slots this frame: bounce VPLs, environment VPLs (their directions added to
// the reuse's lamps), the rest the lamps'. `level_shadowed`: the estimated lights the direct-light
// block's level shadows with maps.
Dir::VplSlots Dir::plan_vpl_slots(const DirLevel& level, int level_shadowed) {
  // Environment VPLs: the strongest regions of the stage's cut, one directional VPL each.
  const std::vector<light::EnvLight>& regions = shared_.light_stage->environment_regions();
  const light::Lighting& lighting = shared_.light_stage->lighting();
  VplSlots slots;
  slots.bounce = bounce_ ? level.bounce_vpls : 0;
  // The regions the direct-light block shades with shadow maps at its level (the first of the
  // light stage's shadowed regions, which may lie anywhere in the cut: only compact, bright,
  // distant ones are shadowed) keep them; the VPLs take the others, strongest first, whose
  // light the block adds unshadowed in its SH ambient.
  size_t shadowed = 0;
  for (uint8_t f : lighting.foldable) shadowed += f != 0 ? 1 : 0;
  // A level that leaves the regions' shadows to the VPLs (shadowed_env >= 0) does so only when
  // there are environment VPLs (else the estimated lights, the probeless one too, keep their maps).
  slots.env_override =
      level.shadowed_env >= 0 && level.env_vpls > 0 && !ablation_.no_environment_vpls && !regions.empty();
  const int map_shadowed = slots.env_override ? level.shadowed_env : level_shadowed;
  const std::vector<size_t>& with_lights = shared_.light_stage->shadowed_environment_regions();
  shadowed = std::min(shadowed, size_t(std::max(0, map_shadowed)));
  slots.parts = level.interleave > 1 ? level.env_parts : 1u;  // parts need the interleaving block
  const uint32_t most = ablation_.no_environment_vpls
                            ? 0u
                            : std::min({level.env_vpls, kMaxEnvVpls / slots.parts,
                                        (level.vpls - slots.bounce - 1) / slots.parts});
  slots.regions = environment_vpl_regions(regions.size(), with_lights, shadowed, most, slots.region.data());
  slots.env = slots.regions * slots.parts;
  for (uint32_t k = 0; k < slots.regions; ++k) {
    LightDesc l;
    l.type = LightType::Directional;
    l.direction = glm::vec3(-regions[slots.region[k]].direction);
    l.color = glm::vec3(regions[slots.region[k]].irradiance);
    reuse_.add_lamp(l);
  }
  return slots;
}

// The maps, VPLs and ISMs of this frame (the bounce light source first: it reads the previous
// frame's VPLs and ISMs).
Status Dir::make_vpls(const frame::FrameInfo& info, const DirLevel& level, const VplSlots& slots, float clamp_m,
                      bool close, std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  const light::Lighting& lighting = shared_.light_stage->lighting();
  const std::vector<light::EnvLight>& regions = shared_.light_stage->environment_regions();
  bounce_generations_ = close ? bounce_generations_ + 1 : 0;
  // The G-buffer's focal lengths in its own pixels (the colour camera's, scaled to its size).
  const VkExtent2D g = graph.extent(shared_.real_position);
  const Intrinsics& c = shared_.color_intrinsics;
  const glm::vec2 focal_px(float(c.fx * double(g.width) / double(std::max(1, c.width))),
                           float(c.fy * double(g.height) / double(std::max(1, c.height))));
  // The bounce light source reads the previous frame's VPLs and ISMs, so it runs first.
  const bool bounce = slots.bounce > 0 && made_.valid;
  if (slots.bounce > 0 && !made_.valid)
    skipped.push_back("dir bounce VPLs: no previous frame's VPLs to bounce (the first frame that makes them)");
  if (bounce) {
    gi::BounceFrame bf;
    bf.slots = slots.bounce;
    bf.source_vpls = made_.vpls;
    bf.source_ism_size = made_.ism_size;
    bf.source_tiles_per_row = made_.tiles_per_row;
    bf.centre = centre_;
    bf.radius = radius_;
    bf.clamp_m = clamp_m;
    bf.bias_relative = kIsmBiasRelative;
    bf.bias_m = kIsmBiasMetres;
    bf.focal_px = focal_px;
    MRGI_TRY(bounce_->add_bounce(graph, vpls_->buffer(), ism_->distances(), bf));
  }
  const uint32_t lamp_vpls = level.vpls - slots.bounce - slots.env;
  // The real grid at about two points a map texel across the G-buffer's larger side (dlpv's rule).
  const uint32_t stride = std::max(1u, uint32_t(std::ceil(double(std::max(g.width, g.height)) / (level.rsm_size / 2.0))));
  vpls_->add_clear(graph);
  if (bounce) MRGI_TRY(vpls_->add_copy(graph, "bounce", bounce_->buffer(), lamp_vpls, slots.bounce));
  if (slots.env > 0) {
    auto* env = static_cast<shader::Vpl*>(graph.mapped(env_vpls_, graph.slot()));
    const float flags = float(MRGI_VPL_VALID | MRGI_VPL_DIRECTIONAL |
                              (shared_.light_stage->environment_real() ? MRGI_VPL_REAL_PATH : 0));
    // Each region as slots.parts equal-energy parts over its extent, part j shading the
    // interleaving block's class j (common/vpl.glsl: specular.xy of a directional VPL).
    const light::EnvSampler* sampler = shared_.light_stage->environment_grid();
    std::array<light::EnvPart, kMaxEnvVpls> parts{};
    for (uint32_t k = 0; k < slots.regions; ++k) {
      const light::EnvLight& r = regions[slots.region[k]];
      if (slots.parts == 1 || sampler == nullptr ||
          sampler->split_light(slots.region[k], int(slots.parts), parts.data()) != int(slots.parts)) {
        for (uint32_t j = 0; j < slots.parts; ++j) parts[j] = {r.direction, r.irradiance, r.solid_angle_sr / slots.parts};
        for (uint32_t j = 0; j < slots.parts; ++j) parts[j].irradiance /= double(slots.parts);
      }
      for (uint32_t j = 0; j < slots.parts; ++j)
        env[k * slots.parts + j] = {glm::vec4(centre_, flags), glm::vec4(glm::vec3(parts[j].direction), radius_),
                                    glm::vec4(glm::vec3(parts[j].irradiance), 0.0f), glm::vec4(0.0f, 0.0f, 1.0f, -1.0f),
                                    glm::vec4(float(j), float(slots.parts), 0.0f, 0.0f)};
    }
    MRGI_TRY(vpls_->add_copy(graph, "environment", env_vpls_, lamp_vpls + slots.bounce, slots.env));
  }
  rsm_->add_grid(graph, stride);
  const uint32_t lamps = uint32_t(planned_.size());
  uint32_t first = 0;
  for (uint32_t k = 0; k < lamps; ++k) {
    const auto& [i, view] = planned_[k];
    const uint32_t count = lamp_vpls / lamps + (k < lamp_vpls % lamps ? 1 : 0);
    if (count == 0) continue;
    const std::string id = std::to_string(i);
    const gi::RsmImages mu = rsm_->images(gi::RsmMap::RealOnly, level.rsm_size);
    const gi::VplLamp lamp{view.light, glm::vec3(view.colour)};
    if (lamp_reaches_objects(lighting.lights[i])) {
      rsm_->add_pair(graph, id, view, level.rsm_size);
      // Caustic VPLs (caustics-DIR Sec. 4.2.2): this lamp's photons, when the specular stage
      // made a caustic map for it this frame.
      std::optional<gi::VplCaustics> caustic;
      if (info.caustics && !ablation_.no_caustic_vpls)
        for (const frame::CausticPhotons::Lamp& c : info.caustics->lamps)
          if (glm::distance(c.position, lighting.lights[i].position) < 1e-4f) caustic = gi::VplCaustics{c.photons, c.view_proj, c.size};
      MRGI_TRY(vpls_->add_sample(graph, id, rsm_->images(gi::RsmMap::WithVirtual, level.rsm_size), mu,
                                 lighting.lights[i].real, lamp, first, count, caustic ? &*caustic : nullptr));
    } else {
      // The spot's cone misses the virtual objects: R^rho would be R^mu's copy, so only R^mu is drawn.
      skipped.push_back("dir rsm rho " + id + ": no virtual object in the lamp's cone (R^mu stands for both maps)");
      rsm_->add_real(graph, id, view, level.rsm_size);
      MRGI_TRY(vpls_->add_sample(graph, id, mu, mu, lighting.lights[i].real, lamp, first, count));
    }
    first += count;
  }
  gi::IsmFrame f;
  f.vpls = level.vpls;
  f.map_size = level.ism_size;
  f.points_per_vpl = level.points_per_vpl;
  f.focal_px = focal_px;
  MRGI_TRY(ism_->add_build(graph, vpls_->buffer(), f));
  reuse_.remember();
  made_ = {true, level.vpls, level.ism_size, ism_->tiles_per_row(level.vpls)};
  return ok_status();
}

// The VPLs' light at the level's resolution (eq. 6-8, interleaved), merged geometry-aware and
// smoothed over frames: the direct-light block's screen input.
Expected<shading::ScreenIndirect> Dir::record_vpl_light(const frame::FrameInfo& info, const DirLevel& level,
                                                        const VplSlots& slots, float clamp_m,
                                                        std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  for (gpu::ImageHandle h : {indirect_, rows_, merged_, smoothed_[0], smoothed_[1]})
    MRGI_TRY(graph.set_extent_divisor(h, level.indirect_divisor));
  const VkExtent2D low = graph.extent(indirect_);
  const DirPush push{glm::ivec4(int(level.vpls), int(level.ism_size), int(ism_->tiles_per_row(level.vpls)),
                                int(level.interleave)),
                     glm::vec4(clamp_m, kIsmBiasRelative, kIsmBiasMetres,
                               !level.real_bounce_beside_camera_ambient &&
                                       shared_.light_stage->lighting().ambient_below_from_camera
                                   ? 1.0f
                                   : 0.0f),
                     glm::ivec4(int(low.width), int(low.height), int(level.indirect_divisor), int(level.vpls - slots.env))};
  const frame::FrameResources& r = shared_;
  const gpu::Pipeline* shade = &*shade_;
  const gpu::BufferHandle vpl_buffer = vpls_->buffer();
  const gpu::ImageHandle distances = ism_->distances(), indirect = indirect_, rows = rows_, merged = merged_;
  graph.add_shader_pass(
      "dir shade vpls", gpu::PassKind::Compute, *shade_,
      [&](gpu::ShaderPassBuilder& b) {
        frame::bind_gbuffer_reads(b, r);
        b.bind("Vpls", vpl_buffer);
        b.bind("ism_distances", distances, 0);
        b.bind("indirect", indirect);
      },
      [shade, push, low](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::dispatch_2d(cmd, *shade, &push, sizeof push, low.width, low.height);
      });
  const gpu::Pipeline* merge_rows = &*merge_rows_;
  graph.add_shader_pass(
      "dir merge rows", gpu::PassKind::Compute, *merge_rows_,
      [&](gpu::ShaderPassBuilder& b) {
        b.bind("indirect", indirect);
        b.bind("rows", rows);
      },
      [merge_rows, push, low](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::dispatch_2d(cmd, *merge_rows, &push, sizeof push, low.width, low.height);
      });
  shading::ScreenIndirect to_add{merged_, int(level.indirect_divisor)};
  if (ablation_.no_temporal_smoothing) {
    skipped.push_back("dir temporal smoothing: off (ablation no-temporal-smoothing)");
    history_.valid = false;
    // The merge's column half as a pass of its own (temporal.comp runs it otherwise).
    const gpu::Pipeline* merge_columns = &*merge_columns_;
    graph.add_shader_pass(
        "dir merge columns", gpu::PassKind::Compute, *merge_columns_,
        [&](gpu::ShaderPassBuilder& b) {
          b.bind("rows", rows);
          b.bind("merged", merged);
        },
        [merge_columns, push, low](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::dispatch_2d(cmd, *merge_columns, &push, sizeof push, low.width, low.height);
        });
  } else {
    // The previous frame's smoothed light is the history while it was made at this level and
    // internal resolution (the same grid and intrinsics: the scheduler moves the resolution
    // inside a level); the pose may differ (reprojected).
    const bool have = history_.valid && history_.level == info.level && history_.width == low.width &&
                      history_.height == low.height;
    const int read = history_.image, write = 1 - history_.image;
    const glm::dmat4 previous = history_.camera_to_world;
    const TemporalPush tp{glm::mat4(glm::inverse(previous)), glm::vec4(glm::vec3(previous[3]), have ? 1.0f : 0.0f),
                          glm::ivec4(int(low.width), int(low.height), int(level.indirect_divisor), int(level.interleave)),
                          glm::vec4(kTemporalBlend, 0.0f, 0.0f, kTemporalChange)};
    const gpu::Pipeline* temporal = &*temporal_;
    const gpu::ImageHandle history = smoothed_[read], smoothed = smoothed_[write];
    graph.add_shader_pass(
        "dir temporal", gpu::PassKind::Compute, *temporal_,
        [&](gpu::ShaderPassBuilder& b) {
          b.bind("FrameUbo", r.frame_constants);
          b.bind("real_position", r.real_position);
          b.bind("virtual_position", r.virtual_position);
          b.bind("rows", rows);
          b.bind("history", history);
          b.bind("smoothed", smoothed);
        },
        [temporal, tp, low](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::dispatch_2d(cmd, *temporal, &tp, sizeof tp, low.width, low.height);
        });
    if (!have)
      skipped.push_back("dir temporal smoothing: no history at this level and resolution yet (the frame's own light)");
    history_ = {true, info.level, write, info.camera_to_world, low.width, low.height};
    to_add.packed = smoothed_[write];
  }
  return to_add;
}

}  // namespace

Expected<std::unique_ptr<Technique>> create_dir(const frame::FrameResources& shared, const TechniqueOptions& options) {
  auto levels = dir_levels(options.knobs);
  if (!levels) return levels.error();
  auto t = std::make_unique<Dir>(shared, std::move(*levels), options.research.dir);
  MRGI_TRY(t->init());
  return std::unique_ptr<Technique>(std::move(t));
}

uint32_t environment_vpl_regions(size_t regions, const std::vector<size_t>& shadowed, size_t mapped, uint32_t most,
                                 uint32_t* out) {
  const auto mapped_end = shadowed.begin() + std::ptrdiff_t(std::min(mapped, shadowed.size()));
  uint32_t n = 0;
  for (size_t r = 0; r < regions && n < most; ++r)
    if (std::find(shadowed.begin(), mapped_end, r) == mapped_end) out[n++] = uint32_t(r);
  return n;
}

}  // namespace mrgi::technique
