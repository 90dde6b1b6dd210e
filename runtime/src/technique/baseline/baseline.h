// The `baseline` technique: direct light only, as most AR apps ship (docs/DESIGN.md "Techniques"): the
// direct-light block (shading/direct_light.h) with no indirect input: the DIR paper's real/virtual
// shadow-map pair per real lamp (no double shadows, eq. 1-5), the light stage's estimated lights
// with maps for the strongest, the rest as SH ambient without occlusion.
//
// Quality ladder (best first):
//   level  name     shadow_map_size  internal_scale  pcf_radius  caster_cell_shadow_texels  shadowed_estimated_lights
//   0      high     2048             1.0             1 (3x3)     2                          4
//   1      medium   1024             1.0             1           2                          4
//   2      low       512             0.75            1           2                          2
//   3      lowest    256             0.5             0 (1 tap)   2                          1
// Units: shadow_map_size in texels per side of each map face; internal_scale as a fraction of
// the output width and height; pcf_radius in bilinear compare taps on each side of the centre
// tap; caster_cell_shadow_texels: map texels a cell of the real caster mesh spans
// (shading/direct_light.h; 640x480 at high: a point every pixel; lowest, 320x240 into 256^2:
// every third); shadowed_estimated_lights: of the light stage's estimated lights, strongest
// first, how many get shadow maps.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "shading/direct_light.h"
#include "technique/technique.h"

namespace mrgi::technique {

// One level of the ladder above, typed (the generic QualityLevel knobs are made from it).
struct BaselineLevel {
  const char* name;
  uint32_t shadow_map_size;         // texels per side of each map face
  float internal_scale;             // fraction of the output width and height
  int pcf_radius;                   // bilinear compare taps on each side of the centre tap
  double caster_cell_shadow_texels; // shadow texels a real caster grid cell spans (see above)
  int shadowed_estimated_lights;    // estimated lights with shadow maps (shading/direct_light.h)
  int env_occlusion_divisor;        // internal pixels a texel side of the environment occlusion
  int env_occlusion_spheres;        // sphere proxies an object that occlude the ambient (0 = off)
  int env_occlusion_regions;        // broad bright regions of the ambient occluded as cones (0..4)
  int env_occlusion_near_field;     // march steps looking for a real surface beyond each proxy
  bool env_occlusion_lights_bounce; // the objects send the shadowed lights' bounce on
  bool env_occlusion_real_bounce;   // the surroundings they darken light the scene less
  float mesh_error_px;              // QualityLevel::mesh_error_px: the virtual G-buffer's level of detail
  float compose_tolerance;          // QualityLevel::compose_tolerance: 8-bit levels a kept tile may miss
};
const std::array<BaselineLevel, 4>& baseline_levels();  // the defaults
// The defaults with RuntimeSettings::knobs applied (technique/knobs.h; BadUsage for a refused one).
Expected<std::vector<BaselineLevel>> baseline_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> baseline_ladder(const std::vector<KnobSetting>& knobs);
Expected<std::unique_ptr<Technique>> create_baseline(const frame::FrameResources& frame, const TechniqueOptions& options);

}  // namespace mrgi::technique
