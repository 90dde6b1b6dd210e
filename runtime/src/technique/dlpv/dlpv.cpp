#include "technique/dlpv/dlpv.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "common/light_set.glsl"
#include "gi/light_propagation.h"
#include "gi/rsm.h"
#include "gpu/pipelines.h"
#include "light/light_stage.h"
#include "gi/input_reuse.h"
#include "technique/knobs.h"
#include "technique/laddered.h"
#include "light/light_set_writer.h"
#include "frame/scene_gpu.h"

namespace mrgi::technique {

const std::array<DlpvLevel, 5>& dlpv_levels() {
  static const std::array<DlpvLevel, 5> levels = {{
      {"paper", 32, 32, 512, 4, true, 1.0f, true, 0, true, 0.0f, 0.5f},
      {"high", 32, 32, 512, 4, true, 1.0f, false, 0, false, 0.0f, 0.5f},
      {"medium", 16, 16, 256, 2, true, 1.0f, false, 1, false, 0.0f, 0.5f},
      {"fast", 8, 8, 128, 1, false, 0.5f, false, 3, false, 0.2f, 1.5f},
      {"fastest", 8, 4, 64, 1, false, 0.5f, false, 3, false, 0.2f, 1.5f},
  }};
  return levels;
}

namespace {
const KnobField<DlpvLevel> kDlpvKnobs[] = {
    {"volume_cells", "cells per side of each volume", &DlpvLevel::volume_cells, true},
    {"steps", "propagation steps", &DlpvLevel::steps},
    {"rsm_size", "texels per side of each reflective shadow map", &DlpvLevel::rsm_size, true},
    {"rsm_lamps", "real lamps, strongest first, with a map pair", &DlpvLevel::rsm_lamps},
    {"rho_volume", "1: V^rho propagated for the virtual pixels", &DlpvLevel::rho_volume},
    {"internal_scale", "fraction of the output width and height", &DlpvLevel::internal_scale},
    {"antiradiance_shadows", "1: shadows as the volume's antiradiance (Algorithm 1); 0: the direct-light block's shadow maps",
     &DlpvLevel::antiradiance_shadows},
    {"baseline_level", "the direct-light block's level for the shadow maps", &DlpvLevel::baseline_level},
    {"rho_beside_bounce_ambient",
     "1: V^rho on virtual pixels also where the ambient already holds the real bounce (residual estimate, env camera); "
     "0: the ambient there",
     &DlpvLevel::rho_beside_bounce_ambient},
    {"mesh_error_px", "largest projected error of the virtual meshes' level of detail (internal pixels; 0 = full detail)",
     &DlpvLevel::mesh_error_px},
    {"compose_tolerance",
     "8-bit levels a tile's composite may move a pixel by and the tile still keep the camera frame (rounding adds up to half a level)",
     &DlpvLevel::compose_tolerance},
};
}  // namespace

Expected<std::vector<DlpvLevel>> dlpv_levels(const std::vector<KnobSetting>& knobs) {
  return apply_knobs<DlpvLevel>("dlpv", dlpv_levels(), kDlpvKnobs, knobs);
}

Expected<std::vector<QualityLevel>> dlpv_ladder(const std::vector<KnobSetting>& knobs) {
  auto levels = dlpv_levels(knobs);
  if (!levels) return levels.error();
  return ladder_of(*levels, dlpv_levels(), kDlpvKnobs);
}

namespace {

struct MergePush {
  glm::vec4 grid;    // min corner, cell size
  glm::vec4 extent;  // cells allocated, cells used, V^Delta present, V^rho present
  glm::ivec4 occlusion{0};  // x: the environment occlusion's divisor (0: none this frame)
};

// The volume around the virtual objects: twice their largest bounding-box edge (paper Sec. 4.2),
// at least 0.25 m (a thin object still has room around it for its shadow and bounce).
constexpr float kMinVolumeSide = 0.25f;

class Dlpv final : public Laddered<DlpvLevel> {
 public:
  Dlpv(const frame::FrameResources& shared, std::vector<DlpvLevel> levels, const DlpvAblation& ablation)
      : Laddered("dlpv", ladder_of(levels, dlpv_levels(), kDlpvKnobs), std::move(levels)),
        shared_(shared), ablation_(ablation) {}
  Status init();
  Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) override;

 private:
  void write_lights();
  // What record_volumes made this frame.
  struct MadeVolumes {
    bool delta = false, rho = false;  // V^Delta (V^rho - V^mu in the ablation) and V^rho present
    MergePush push{};                 // the lookup's grid and extent
  };
  Status record_volumes(const frame::FrameInfo& info, const DlpvLevel& level, MadeVolumes& made,
                        std::vector<std::string>& skipped);
  uint32_t inject_lamps(const DlpvLevel& level, bool rho, float radius, uint32_t stride, std::vector<std::string>& skipped);
  void add_merge_pass(const MergePush& push, gpu::ImageHandle env_occlusion);

  frame::FrameResources shared_;
  gpu::BufferHandle lights_;  // shader::LightSet, one per frame slot
  std::optional<gi::ReflectiveShadowMaps> rsm_;
  std::optional<gi::LightPropagationVolume> delta_, rho_;
  std::optional<gi::LightPropagationVolume> mu_;  // DlpvAblation::two_volumes only
  gpu::PipelineHandle merge_;
  DlpvAblation ablation_;  // TechniqueOptions::research
  // Direct light with shadow maps (not the antiradiance levels), the volumes as its input.
  std::unique_ptr<shading::DirectLightBlock> direct_;
  std::optional<shading::DirectLightOutput> direct_light() const override { return direct_->output(); }
  gi::InputReuse reuse_;                    // what the volumes in the images were made from
  bool source_delta_ = false, source_rho_ = false;  // which volumes that frame made
  bool has_virtual_ = false;
  glm::vec3 centre_{0.0f};
  float side_ = 1.0f;
  uint64_t sized_for_layout_ = ~uint64_t(0);  // the SceneGpu::layout_revision side_ was set for
};

Status Dlpv::init() {
  gpu::FrameGraph& graph = *shared_.graph;
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (!shared_.light_stage) return fail(ErrorKind::Internal, "dlpv: no light stage");
  auto lights = graph.create_buffer({"dlpv_lights", sizeof(shader::LightSet), gpu::MemoryUsage::Upload, true},
                                    VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!lights) return lights.error();
  lights_ = *lights;
  has_virtual_ = sg.may_have_objects();
  uint32_t top_cells = 2, top_rsm = 16;
  if (has_virtual_) {
    const glm::vec3 size = sg.virtual_objects.bounds_max - sg.virtual_objects.bounds_min;
    centre_ = 0.5f * (sg.virtual_objects.bounds_max + sg.virtual_objects.bounds_min);
    side_ = std::max(kMinVolumeSide, 2.0f * std::max({size.x, size.y, size.z}));
    sized_for_layout_ = sg.layout_revision();
    for (const DlpvLevel& l : levels_) {
      top_cells = std::max(top_cells, l.volume_cells);
      top_rsm = std::max(top_rsm, l.rsm_size);
    }
    gi::RsmSettings rs;
    rs.name = "dlpv rsm";
    rs.size = top_rsm;
    auto rsm = gi::ReflectiveShadowMaps::create(
        graph, sg, {shared_.real_position, shared_.real_normal, shared_.real_albedo}, rs);
    if (!rsm) return rsm.error();
    rsm_.emplace(std::move(*rsm));
  }
  // Without virtual objects nothing is injected; the volumes are then 2^3, allocated only so the
  // merge binds images of the kind it declares (it reads none of them).
  const DlpvAblation& ablation = ablation_;
  gi::LpvSettings ds;
  ds.name = "dlpv delta";
  ds.resolution = top_cells;
  ds.negative_damping = ablation.no_negative_damping ? 0.0f : 1.0f;
  ds.vpl_shift_cells = ablation.no_half_cell_shift ? 0.0f : 0.5f;
  auto delta = gi::LightPropagationVolume::create(graph, ds);
  if (!delta) return delta.error();
  delta_.emplace(std::move(*delta));
  gi::LpvSettings ps = ds;
  ps.name = "dlpv rho";
  ps.negative_damping = 0.0f;  // V^rho holds no antiradiance
  auto rho = gi::LightPropagationVolume::create(graph, ps);
  if (!rho) return rho.error();
  rho_.emplace(std::move(*rho));
  if (ablation.two_volumes) {
    gi::LpvSettings ms = ps;
    ms.name = "dlpv mu";
    auto mu = gi::LightPropagationVolume::create(graph, ms);
    if (!mu) return mu.error();
    mu_.emplace(std::move(*mu));
  }
  auto merge = gpu::load_compute_pipeline(*shared_.context, "dlpv/merge.comp", {});
  if (!merge) return merge.error();
  merge_ = std::move(*merge);
  reuse_.reserve(size_t(shared_.depth_intrinsics.width) * size_t(shared_.depth_intrinsics.height), shared_.depth_scale);
  shading::DirectLightOptions direct;
  direct.volume_indirect = true;
  auto block = shading::DirectLightBlock::create(shared_, direct);
  if (!block) return block.error();
  direct_ = std::move(*block);
  return ok_status();
}

void Dlpv::write_lights() {
  auto* set = static_cast<shader::LightSet*>(shared_.graph->mapped(lights_, shared_.graph->slot()));
  light::write_unshadowed_light_set(shared_.light_stage->lighting(), *set);
}

Status Dlpv::record(const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  direct_->begin_frame();
  auto level_or = level_for(info);
  if (!level_or) return level_or.error();
  const DlpvLevel& level = **level_or;
  const bool antiradiance = level.antiradiance_shadows;
  const bool two = mu_.has_value();  // DlpvAblation::two_volumes
  if (two && antiradiance)
    return fail(ErrorKind::BadUsage, std::string("dlpv: the two-volume ablation (DlpvAblation::two_volumes) needs a level "
                                                 "with shadow-mapped direct light; level '") + level.name +
                                         "' shadows with V^Delta's antiradiance");
  write_lights();
  MadeVolumes made;
  MRGI_TRY(record_volumes(info, level, made, skipped));
  if (antiradiance) {
    // The volume's antiradiance shadows the lamps it injects; the ambient's occlusion by the
    // objects is the direct-light block's, as at the other levels.
    // V^Delta carries the lamps' bounce off the objects: the block's occlusion leaves it out.
    shading::EnvOcclusionLevel occlusion_level = shading::direct_light_levels()[size_t(level.baseline_level)].env_occlusion;
    occlusion_level.lights_bounce = false;
    occlusion_level.real_bounce_loss_lights = false;
    const auto occlusion = direct_->record_env_occlusion(occlusion_level, skipped);
    made.push.occlusion.x = occlusion.divisor;
    add_merge_pass(made.push, occlusion.image);
    return ok_status();
  }
  const gpu::ImageHandle dvol[3] = {delta_->accumulated(0), delta_->accumulated(1), delta_->accumulated(2)};
  const gpu::ImageHandle rvol[3] = {rho_->accumulated(0), rho_->accumulated(1), rho_->accumulated(2)};
  // Direct light and its shadows: the direct-light block at the matching level writes both
  // solutions, recorded after the volumes so that its shading adds their bounce light in the
  // same pass (its volume input): V^Delta on real pixels (the two-volume ablation: V^rho minus
  // V^mu), V^rho on virtual ones.
  shading::DirectLightLevel direct = shading::direct_light_levels()[size_t(level.baseline_level)];
  if (!(made.delta || made.rho)) return direct_->record(info, direct, {}, skipped);
  // The volumes carry the lamps' bounce off the objects: the block's occlusion leaves it out.
  direct.env_occlusion.lights_bounce = false;
  direct.env_occlusion.real_bounce_loss_lights = false;  // and V^Delta the light the shadows keep from the ground
  shading::VolumeIndirect bounce;
  bounce.real_term = two ? shading::VolumeIndirect::RealTerm::Difference : shading::VolumeIndirect::RealTerm::One;
  bounce.virtual_present = made.rho;
  for (uint32_t c = 0; c < 3; ++c) {
    bounce.real[c] = two ? rvol[c] : dvol[c];
    bounce.subtract[c] = two ? mu_->accumulated(c) : dvol[c];
    bounce.virtual_[c] = rvol[c];
  }
  bounce.constants = {made.push.grid, made.push.extent};
  return direct_->record(info, direct, bounce, skipped);
}

// The volumes this frame: V^Delta (and V^rho where the level has it; V^rho and V^mu in the
// two-volume ablation) injected from the real lamps' map pairs and propagated, or kept from the
// frame that made them. Fills `made` with which are present and the lookup's constants.
Status Dlpv::record_volumes(const frame::FrameInfo& info, const DlpvLevel& level, MadeVolumes& made,
                            std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  const bool two = mu_.has_value();  // DlpvAblation::two_volumes
  const light::Lighting& lighting = shared_.light_stage->lighting();
  bool& delta_present = made.delta;
  bool& rho_present = made.rho;
  MergePush& push = made.push;
  if (!has_virtual_) {
    skipped.push_back("dlpv volumes: no virtual object in the scene");
  } else {
    MRGI_TRY(delta_->set_cells(graph, level.volume_cells));
    MRGI_TRY(rho_->set_cells(graph, level.volume_cells));
    // The volumes follow the objects. Their side is set when the objects are (start-up, an
    // object added or removed: SceneGpu::layout_revision), not as they move: rigid motion keeps it.
    const frame::SceneGpu& sg = *shared_.scene_gpu;
    centre_ = 0.5f * (sg.virtual_objects.bounds_max + sg.virtual_objects.bounds_min);
    if (sized_for_layout_ != sg.layout_revision()) {
      const glm::vec3 size = sg.virtual_objects.empty() ? glm::vec3(0.0f) : sg.virtual_objects.bounds_max - sg.virtual_objects.bounds_min;
      side_ = std::max(kMinVolumeSide, 2.0f * std::max({size.x, size.y, size.z}));
      sized_for_layout_ = sg.layout_revision();
    }
    const gi::LpvGrid grid{centre_ - glm::vec3(0.5f * side_), side_ / float(level.volume_cells)};
    delta_->set_grid(grid);
    rho_->set_grid(grid);
    if (two) {
      MRGI_TRY(mu_->set_cells(graph, level.volume_cells));
      mu_->set_grid(grid);
    }
    push.grid = glm::vec4(grid.origin, grid.cell_size);
    const float radius = 0.5f * side_ * std::sqrt(3.0f);
    // The real grid at about two points a map texel across the G-buffer's larger side.
    const VkExtent2D g = graph.extent(shared_.real_position);
    const uint32_t stride = std::max(1u, uint32_t(std::ceil(double(std::max(g.width, g.height)) / (level.rsm_size / 2.0))));
    // The real lamps the maps are drawn for this level (strongest first), as the reuse compares them.
    reuse_.set_frame(info.level, info.camera_to_world, info.camera, shared_.scene_gpu->revision());
    for (size_t i = 0, n = 0; i < lighting.lights.size() && n < level.rsm_lamps; ++i)
      if (lighting.lights[i].real) {
        reuse_.add_lamp(lighting.lights[i]);
        ++n;
      }
    // V^rho this frame (DlpvLevel::rho_beside_bounce_ambient).
    const bool rho = level.rho_volume && (level.rho_beside_bounce_ambient || !lighting.ambient_holds_real_bounce);
    const bool reuse = reuse_.close() && (two || source_rho_ == rho);
    uint32_t lamps = 0;
    if (reuse) {
      lamps = uint32_t(reuse_.lamp_count());
      skipped.push_back("dlpv maps and volumes: reused (level, pose, depth and lamps within tolerance of the frame that made them)");
    }
    if (!reuse) lamps = inject_lamps(level, rho, radius, stride, skipped);
    if (reuse) {
      delta_present = source_delta_;
      rho_present = source_rho_;
    } else if (lamps == 0) {
      skipped.push_back("dlpv volumes: no real light to inject (no lamp, environment region or estimate)");
    } else if (two) {
      // The ablation: V^rho and V^mu propagated apart; real pixels look up their difference.
      rho_->add_propagate(graph, level.steps);
      mu_->add_propagate(graph, level.steps);
      delta_present = true;
      rho_present = level.rho_volume;
    } else {
      delta_->add_propagate(graph, level.steps);
      delta_present = true;
      if (rho) {
        rho_->add_propagate(graph, level.steps);
        rho_present = true;
      }
    }
    if (!level.rho_volume)
      skipped.push_back("dlpv rho volume: level '" + std::string(level.name) +
                        "' shades virtual pixels with lamps and ambient only");
    else if (!rho && !two)
      skipped.push_back("dlpv rho volume: the ambient already holds the real scene's bounce; virtual pixels take it");
    if (!reuse) {
      // Remembered only when made from a depth frame the next one can be compared with.
      reuse_.remember();
      source_delta_ = delta_present;
      source_rho_ = rho_present;
    }
    push.extent = glm::vec4(float(delta_->settings().resolution), float(level.volume_cells), delta_present ? 1.0f : 0.0f,
                            rho_present ? 1.0f : 0.0f);
  }
  return ok_status();
}

// Each real lamp's map pair (strongest first, the level's number) injected: V^Delta from the
// texels the objects change, V^rho (and V^mu in the ablation), V^Delta's antiradiance at the
// paper level. Returns the lamps injected.
uint32_t Dlpv::inject_lamps(const DlpvLevel& level, bool rho, float radius, uint32_t stride,
                            std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  const bool antiradiance = level.antiradiance_shadows;
  const bool two = mu_.has_value();  // DlpvAblation::two_volumes
  const light::Lighting& lighting = shared_.light_stage->lighting();
  bool grid_added = false;
  uint32_t lamps = 0;
  for (size_t i = 0; i < lighting.lights.size() && lamps < level.rsm_lamps; ++i) {
    const LightDesc& lamp = lighting.lights[i];
    if (!lamp.real) continue;
    auto view = gi::rsm_view(lamp, centre_, radius, level.rsm_size);
    if (!view) {
      skipped.push_back("dlpv rsm (light " + std::to_string(i) + "): " + view.error().message);
      continue;
    }
    if (!grid_added) {
      if (two) {
        rho_->add_clear(graph);
        mu_->add_clear(graph);
      } else {
        delta_->add_clear(graph);
        if (rho) rho_->add_clear(graph);
      }
      rsm_->add_grid(graph, stride);
      grid_added = true;
    }
    const std::string id = std::to_string(i);
    const gi::RsmImages rho_map = rsm_->images(gi::RsmMap::WithVirtual, level.rsm_size);
    const gi::RsmImages mu_map = rsm_->images(gi::RsmMap::RealOnly, level.rsm_size);
    rsm_->add_pair(graph, id, *view, level.rsm_size);
    // V^Delta = R^rho's VPLs - R^mu's, from the texels the virtual objects cover (the rest
    // cancel exactly, rsm.h), in one pass.
    if (!two) delta_->add_inject(graph, "delta " + id, rho_map, view->lpv, gi::InjectKind::Indirect, 1.0f, &mu_map);
    if (rho || two)
      rho_->add_inject(graph, "rho " + id, rho_map, view->lpv,
                       !two && ablation_.no_virtual_self_bounce ? gi::InjectKind::IndirectFromReal
                                                                            : gi::InjectKind::Indirect,
                       1.0f);
    if (two) mu_->add_inject(graph, "mu " + id, mu_map, view->lpv, gi::InjectKind::Indirect, 1.0f);
    if (antiradiance)
      delta_->add_inject(graph, "blocked direct " + id, mu_map, view->lpv, gi::InjectKind::Direct, -1.0f, &rho_map);
    ++lamps;
  }
  return lamps;
}

// The antiradiance levels' own shading (dlpv/merge.comp): lamps unshadowed, V^Delta's
// antiradiance for their shadows and its bounce, V^rho on virtual pixels.
void Dlpv::add_merge_pass(const MergePush& push, gpu::ImageHandle env_occlusion) {
  gpu::FrameGraph& graph = *shared_.graph;
  const frame::FrameResources& r = shared_;
  const gpu::Pipeline* merge = &*merge_;
  const VkSampler linear = shared_.context->samplers().linear_clamp;
  const gpu::ImageHandle dvol[3] = {delta_->accumulated(0), delta_->accumulated(1), delta_->accumulated(2)};
  const gpu::ImageHandle rvol[3] = {rho_->accumulated(0), rho_->accumulated(1), rho_->accumulated(2)};
  graph.add_shader_pass(
      "dlpv merge", gpu::PassKind::Compute, *merge_,
      [&](gpu::ShaderPassBuilder& b) {
        frame::bind_shading_gbuffers(b, r);
        b.bind("LightUbo", lights_);
        b.bind("env_occlusion", env_occlusion);
        const char* d[3] = {"delta_r", "delta_g", "delta_b"};
        const char* p[3] = {"rho_r", "rho_g", "rho_b"};
        for (int c = 0; c < 3; ++c) {
          b.bind_sampled(d[c], dvol[c], linear);
          b.bind_sampled(p[c], rvol[c], linear);
        }
      },
      [merge, push, lit = r.lit_rv](VkCommandBuffer cmd, gpu::PassContext& p) {
        const VkExtent2D e = p.extent(lit);
        gpu::push_and_dispatch(cmd, *merge, &push, sizeof push, {(e.width + 7) / 8, (e.height + 7) / 8, 1});
      });
}


}  // namespace

Expected<std::unique_ptr<Technique>> create_dlpv(const frame::FrameResources& shared, const TechniqueOptions& options) {
  auto levels = dlpv_levels(options.knobs);
  if (!levels) return levels.error();
  auto t = std::make_unique<Dlpv>(shared, std::move(*levels), options.research.dlpv);
  MRGI_TRY(t->init());
  return std::unique_ptr<Technique>(std::move(t));
}

}  // namespace mrgi::technique
