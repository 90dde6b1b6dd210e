// The `baseline` technique: direct light only, as most AR apps ship (DESIGN.md "Techniques"),
// with the DIR paper's real/virtual shadow-map pair per real lamp (no double shadows, eq. 1-5).
// No indirect light. With an environment in scene.json a constant ambient from its mean radiance
// is added (runtime/, FrameConstants::ambient_*), without occlusion.
//
// Quality ladder (best first):
//   level  name     shadow_map_size  internal_scale  pcf_radius  caster_cell_shadow_texels
//   0      high     2048             1.0             1 (3x3)     2
//   1      medium   1024             1.0             1           2
//   2      low       512             0.75            1           2
//   3      lowest    256             0.5             0 (1 tap)   2
// Units: shadow_map_size in texels per side of each map face; internal_scale as a fraction of
// the output width and height; pcf_radius in bilinear compare taps on each side of the centre
// tap; caster_cell_shadow_texels: the real caster mesh (the depth-camera grid drawn into the
// real-caster maps) has one point every ceil(side / (shadow_map_size / this)) G-buffer pixels,
// side = the G-buffer's larger side, so its cells match what the map can resolve (640x480 at
// high: every pixel; lowest, 320x240 into 256^2: every third). Built once a frame as an indexed
// mesh (pass shadow_caster_mesh), so each point is shaded once per face; the grid of one
// unshared vertex triple per triangle it replaced cost 100+ ms at high (1.8 M vertices).
// Maps are allocated at 2048 for every lamp at start-up; lower levels render into and read the
// top-left corner, so set_level never allocates.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "technique/technique.h"

namespace mrgi::technique {

// One level of the ladder above, typed (the generic QualityLevel knobs are made from it).
struct BaselineLevel {
  const char* name;
  uint32_t shadow_map_size;         // texels per side of each map face
  float internal_scale;             // fraction of the output width and height
  int pcf_radius;                   // bilinear compare taps on each side of the centre tap
  double caster_cell_shadow_texels; // shadow texels a real caster grid cell spans (see above)
  // Of the light stage's estimated lights (environment regions, the probeless dominant light),
  // strongest first, how many get shadow maps; the rest light as SH ambient. Each costs two
  // maps and a shading term (env_fisheye, 4 at every level, session 12: high 461 ms, lowest
  // 75 ms against 49 and 25 with none).
  int shadowed_estimated_lights;
};
const std::array<BaselineLevel, 4>& baseline_levels();  // the defaults
// The defaults with RuntimeSettings::knobs applied (technique/knobs.h; BadUsage for a refused one).
Expected<std::vector<BaselineLevel>> baseline_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> baseline_ladder(const std::vector<KnobSetting>& knobs);

// The bounce light of dlpv's volumes, added in baseline's shading pass
// (shaders/baseline/shade_direct.comp, kVolumeBounce) instead of a pass of its own.
struct VolumeBounce {
  gpu::ImageHandle delta[3], rho[3];  // V^Delta and V^rho, per colour channel (sampler3D)
  gpu::ImageHandle mu[3];             // V^mu (two_volumes only; else any of the above)
  struct Constants {
    glm::vec4 grid;    // xyz: the volumes' min corner (m); w: cell size (m)
    glm::vec4 extent;  // x: cells allocated per side; y: cells used; z: 1 = V^Delta present; w: 1 = V^rho
    glm::ivec4 mode;   // x: 1 = DlpvAblation::two_volumes (real pixels: E(V^rho) - E(V^mu))
  } constants;
};
// For the next record() of `baseline` (a technique made by create_baseline; others ignore it);
// nullptr: none. The images must be written by passes recorded before that record().
void set_volume_bounce(Technique& baseline, const VolumeBounce* bounce);

// dir's merged VPL light (technique/dir, shaders/dir/indirect_pack.glsl), added to both
// solutions in baseline's shading pass (shade_direct.comp kVolumeBounce bit 8), up-sampled from
// `divisor` x `divisor` G-buffer pixels a texel. Exclusive with a VolumeBounce.
struct DirIndirect {
  gpu::ImageHandle merged;  // RGBA32UI
  int divisor = 1;
  // Of the estimated lights, how many get shadow maps this frame instead of the level's
  // BaselineLevel::shadowed_estimated_lights (-1: the level's); the rest light as SH ambient
  // (dir's fast levels: its environment VPLs shadow them).
  int shadowed_estimated = -1;
};
// As set_volume_bounce: for the next record(); nullptr: none.
void set_dir_indirect(Technique& baseline, const DirIndirect* indirect);
Expected<std::unique_ptr<Technique>> create_baseline(const SharedResources& shared);

}  // namespace mrgi::technique
