#include "technique/baseline/baseline.h"

#include <string>

#include "technique/knobs.h"
#include "technique/laddered.h"

namespace mrgi::technique {
namespace {

const KnobField<BaselineLevel> kBaselineKnobs[] = {
    {"shadow_map_size", "texels per side of each map face", &BaselineLevel::shadow_map_size, true},
    {"internal_scale", "fraction of the output width and height", &BaselineLevel::internal_scale},
    {"pcf_radius", "compare taps on each side of the centre tap", &BaselineLevel::pcf_radius},
    {"caster_cell_shadow_texels", "shadow texels a real caster grid cell spans across the G-buffer's larger side",
     &BaselineLevel::caster_cell_shadow_texels},
    {"shadowed_estimated_lights",
     "of the light stage's estimated lights (environment regions, the probeless dominant light), strongest first, "
     "how many get shadow maps; the rest light as SH ambient",
     &BaselineLevel::shadowed_estimated_lights},
    {"env_occlusion_divisor", "internal pixels a texel side of the virtual objects' occlusion of the ambient light (1-8)",
     &BaselineLevel::env_occlusion_divisor},
    {"env_occlusion_spheres", "sphere proxies an object that occlude the ambient light (0 = off, at most 16)",
     &BaselineLevel::env_occlusion_spheres},
    {"env_occlusion_regions", "broad bright regions of the ambient light the objects hide as cones, not through its SH (0-4)",
     &BaselineLevel::env_occlusion_regions},
    {"env_occlusion_near_field",
     "march steps of each sphere proxy's ray past it that looks for a real surface beyond, whose radiance the proxy "
     "hides instead of the environment's",
     &BaselineLevel::env_occlusion_near_field},
    {"env_occlusion_lights_bounce",
     "what the objects show in place of what they hide includes the shadowed lights' bounce off them (0 = off, 1 = on)",
     &BaselineLevel::env_occlusion_lights_bounce},
    {"mesh_error_px", "largest projected error of the virtual meshes' level of detail (internal pixels; 0 = full detail)",
     &BaselineLevel::mesh_error_px},
    {"env_occlusion_real_bounce",
     "the real surfaces round the objects, darkened by them, light the rest of the scene less (0 = off, 1 = on)",
     &BaselineLevel::env_occlusion_real_bounce},
    {"compose_tolerance",
     "8-bit levels a tile's composite may move a pixel by and the tile still keep the camera frame (rounding adds up to half a level)",
     &BaselineLevel::compose_tolerance},
};

shading::DirectLightLevel direct_level(const BaselineLevel& l) {
  return {l.shadow_map_size, l.pcf_radius, l.caster_cell_shadow_texels, l.shadowed_estimated_lights,
          {l.env_occlusion_divisor, l.env_occlusion_spheres, l.env_occlusion_regions, l.env_occlusion_near_field,
           shading::EnvOcclusionLevel{}.near_field_m, l.env_occlusion_lights_bounce, l.env_occlusion_real_bounce}};
}

class Baseline final : public Laddered<BaselineLevel> {
 public:
  Baseline(std::vector<BaselineLevel> levels, std::unique_ptr<shading::DirectLightBlock> direct)
      : Laddered("baseline", ladder_of(levels, baseline_levels(), kBaselineKnobs), std::move(levels)),
        direct_(std::move(direct)) {}
  Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) override {
    auto level = level_for(info);
    if (!level) return level.error();
    return direct_->record(info, direct_level(**level), {}, skipped);
  }
  std::optional<shading::DirectLightOutput> direct_light() const override { return direct_->output(); }

 private:
  std::unique_ptr<shading::DirectLightBlock> direct_;
};

}  // namespace

const std::array<BaselineLevel, 4>& baseline_levels() {
  static const std::array<BaselineLevel, 4> levels = [] {
    const auto& d = shading::direct_light_levels();
    const char* names[4] = {"high", "medium", "low", "lowest"};
    const float scales[4] = {1.0f, 1.0f, 0.75f, 0.5f};
    // The lowest level draws the virtual G-buffer at the meshes' level of detail within 0.2
    // internal pixels: the sample's bunny (16k triangles) costs 6-10 CPU-ms at full detail, 4-6
    // at 0.2, for +0.0002-0.0066 RDE (glossy_table's glossy bunny the most: its shading normals
    // spread over larger triangles); 0.3 costs glossy_table +0.026, 0.5 +0.059.
    // Perf/results/direct-light-block/mesh-lod-lowest-2026-12-06.md.
    const float mesh_error_px[4] = {0.0f, 0.0f, 0.0f, 0.2f};
    // QualityLevel::compose_tolerance says why the lowest level keeps more tiles as the camera's.
    const float compose_tolerance[4] = {0.5f, 0.5f, 0.5f, 1.5f};
    std::array<BaselineLevel, 4> out{};
    for (size_t i = 0; i < 4; ++i)
      out[i] = {names[i], d[i].shadow_map_size, scales[i], d[i].pcf_radius, d[i].caster_cell_shadow_texels,
                d[i].shadowed_estimated_lights, d[i].env_occlusion.divisor, d[i].env_occlusion.spheres_per_object,
                d[i].env_occlusion.regions, d[i].env_occlusion.near_field_steps, d[i].env_occlusion.lights_bounce,
                d[i].env_occlusion.real_bounce_loss, mesh_error_px[i], compose_tolerance[i]};
    return out;
  }();
  return levels;
}

Expected<std::vector<BaselineLevel>> baseline_levels(const std::vector<KnobSetting>& knobs) {
  return apply_knobs<BaselineLevel>("baseline", baseline_levels(), kBaselineKnobs, knobs);
}

Expected<std::vector<QualityLevel>> baseline_ladder(const std::vector<KnobSetting>& knobs) {
  auto levels = baseline_levels(knobs);
  if (!levels) return levels.error();
  return ladder_of(*levels, baseline_levels(), kBaselineKnobs);
}

Expected<std::unique_ptr<Technique>> create_baseline(const frame::FrameResources& frame, const TechniqueOptions& options) {
  auto levels = baseline_levels(options.knobs);
  if (!levels) return levels.error();
  auto direct = shading::DirectLightBlock::create(frame, {});
  if (!direct) return direct.error();
  return std::unique_ptr<Technique>(std::make_unique<Baseline>(std::move(*levels), std::move(*direct)));
}

}  // namespace mrgi::technique
