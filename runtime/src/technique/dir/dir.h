// The `dir` technique: Differential Instant Radiosity (Knecht et al., "Reciprocal Shading for
// Mixed Reality", ../shared/papers/differential-instant-radiosity-reciprocal-shading.md). Per
// lamp of the light stage (declared lamps, environment regions, the probeless light), the pair of
// reflective shadow maps (gi/rsm.h) gives VPLs by importance with the paper's path flags
// (gi/vpl.h, Sec. 3.7); each VPL gets a real and a virtual imperfect shadow map (gi/ism.h,
// Sec. 3.3); one pass shades every pixel's share of the VPLs into both solutions with the flags
// (shaders/dir/shade_vpl.comp, eq. 6-8), interleaved 4x4 and merged geometry-aware
// (shaders/dir/merge_rows.comp, dir/merge_column.glsl: separable; the column half runs inside
// the temporal smoothing's pass when that is on); the direct-light block's shading pass adds it
// to both solutions with its direct light, at the level's baseline level: the same
// real/virtual shadow-map pair per lamp, eq. 1-5. Beside the lamps' VPLs: the bounce light
// source's (gi/vpl_bounce.h: VPLs lit by last frame's, eq. 9-10, multiple bounces over frames)
// and the environment's (directional VPLs, one per median-cut region); the merged light is
// smoothed over frames (shaders/dir/temporal.comp) before the direct-light block adds it.
//
// Quality ladder (best first; DirLevel below, with units):
//   level    VPLs  bounce  env  ISM    points/VPL  RSM    RSM lamps  interleave  indirect  scale  baseline
//   paper    256   64      16   128^2  1024        512^2  4          4x4         1         1.0    high
//   high     256   64       0    64^2   512        256^2  4          4x4         1         1.0    high
//   medium    64   16       0    64^2   512        256^2  2          4x4         1         1.0    medium
//   fast      32    0       0    32^2   256         64^2  1          4x4         1/2       0.5    lowest
//   fastest   16    0       0    32^2   128         64^2  1          4x4         1/2       0.5    lowest
// "bounce": of the VPLs, the slots of the bounce light source (gi/vpl_bounce.h: multiple bounces
// over frames; 0: one bounce, the fast path). "env": of the VPLs, at most this many
// environment VPLs (Sec. 3.7): the light stage's median-cut regions after those the direct-light block shades
// with shadow maps at its level, each a directional VPL with an orthographic ISM over the
// influence sphere, shaded at every pixel (not interleaved: it is direct light); its light is in
// the direct-light block's SH ambient, unshadowed, so the VPL adds what its maps take away (below). The rest
// of the slots are the lamps'. "indirect": the VPL light is shaded at this fraction of the
// internal resolution and up-sampled geometry-aware in the direct-light block's shading pass. "scale": internal scale, the fraction of the output's side.
// "paper" is the paper's settings (Sec. 6: 256 VPLs, 128^2 ISMs, 1024 points a VPL, 4x4 split).
// Only the paper level draws environment VPLs: at the others the environment's share is the
// direct-light block's (its shadow maps for compact sources, its environment occlusion for the
// rest) and the VPLs carry the lamps' bounce. Measured with the environment VPLs and without
// (all-pixel RDE, 3 frames): window_room_duck high 0.595 -> 0.429, fast 0.551 -> 0.423;
// spot_in_fisheye high 0.422 -> 0.339, fast 0.396 -> 0.264; moving high 0.338 -> 0.290, fast
// 0.514 -> 0.442; dark_sphere_spot high 0.131 -> 0.128; glass_mirror high 0.474 -> 0.483, fast
// equal (the Cycles tuning half and the suite): their imperfect shadow maps darkened the real
// scene in blocky patches, up to 40 % more than the truth (perf/results/env-occlusion/).
// The fast levels' RSMs are 64^2: on lavapipe a map's cost is the real grid's triangles (a grid
// point every two map texels: 128^2 took 1.5-2.3 ms at fast on corner, 64^2 0.55 ms), and 32
// VPLs drawn from 4,096 texels lost nothing measurable (dir fast over the suite's five scenes
// with virtual objects, RDE all: mean 0.751 at 128^2, 0.746 at 64^2; desk_spot 0.326 -> 0.337,
// glass_mirror 0.967 -> 0.910).
//
// Where mrgi differs from the paper and why:
//   - the paper's two RSMs per real lamp (real casters; virtual casters) are gi/rsm.h's pair
//     (R^mu: real casters; R^rho: R^mu with the virtual objects drawn over it): R^rho's virtual
//     texels are the virtual map's texels the lamp reaches, and a real texel R^rho covers is the
//     paper's VPL 3 (ir = 1); a virtual surface behind a real one, which only the paper's
//     virtual map holds, lights neither solution, so nothing is lost;
//   - each map is fitted to the sphere around the virtual objects (twice their largest extent,
//     as dlpv's volume), not to the whole lamp cone: the bounce that differs between the
//     solutions starts there;
//   - ISMs are splatted in compute with atomic min (lavapipe rasterises points on one thread)
//     onto paraboloid maps (the paper's are hemispherical too) and filled by a two-level
//     pull-push;
//   - interleaved sampling runs in place instead of on a split G-buffer (shade_vpl.comp says why);
//   - the VPLs' 1 / d^2 is clamped at the radius of the disk a VPL stands for (the map's area
//     over the VPL count): the paper does not say how it bounds it;
//   - the bounce light source keeps one candidate a slot drawn in proportion to its flux, not the
//     strongest (shaders/gi/vpl_bounce.comp: the maximum biases the sum);
//   - environment VPLs are the light stage's median-cut regions (equal-energy regions: importance
//     sampling, as the paper's hierarchical warping of the fisheye image) as directional VPLs with
//     orthographic ISMs, not point VPLs on a hemisphere (a point a few radii out lights the
//     sphere's near side several times its far side and sees it through a few texels); and they
//     correct the direct-light block's unshadowed ambient instead of carrying the light themselves: on real
//     pixels L_rv gets L_o (min(st_r, st_v) - st_r), the paper's L_rv - L_r of the VPL, while L_r
//     keeps the direct-light block's smooth level (the composite divides by it; the sparse real ISM's
//     self-shadowing made it noisy: env_fisheye real RDE 1.31 carrying the light, 0.87 so); on
//     virtual pixels L_o (min(st_r, st_v) - 1), so L_rv holds the region's light times its
//     visibility as the paper's. The strongest regions keep the direct-light block's shadow maps;
//   - temporal smoothing (the paper's [4]) reprojects the previous frame's smoothed light by the
//     pose and blends it by a confidence from the change of normal and camera distance (the
//     merge's same-surface test on the reprojected taps) and of the light's luminance
//     (shaders/dir/temporal.comp), after the merge, at the indirect light's resolution;
//   - glossy VPLs (the paper's Phong D_I/S_I/S_P becomes glTF's GGX metallic-roughness): a VPL
//     on a glossy virtual surface splits into a cosine emitter and a specular lobe around the
//     mirror direction of its light (shared/vpl_math.h vpl_intensity; the diffuse part scaled by
//     1 - F0, brdf()'s 1 - F at normal incidence), at least MRGI_VPL_MIN_ROUGHNESS wide (a VPL
//     stands for its share of the maps, not a point); virtual pixels reflect VPL light by their
//     whole BRDF; real surfaces stay diffuse (the paper's real specular is 0). The lobe's
//     Schlick grazing term takes the incident flux as grey.
// Ablations (mrgi/research.h DirAblation, `mrgi replay --dir-ablation`): one shadow map a lamp
// and one ISM a VPL instead of two (the lamps' direct light too: the direct-light block's shading pass reads its
// two maps as one, shading/direct_light.comp kOneShadowMap), no ir(VPL), one bounce, no environment
// VPLs, no temporal smoothing (these four change the VPL light only).
//
// Skips (each in FrameStats::skipped):
//   - no glossy virtual material (frame/scene_gpu.h frame::SceneGpu::glossy): no lobes (the shading
//     and bounce pipelines are compiled without them), every VPL diffuse;
//   - no virtual object, or no lamp a map can see them from: no maps, VPLs or ISMs (the direct-light block only);
//   - a spot lamp whose outer cone misses every virtual mesh range's bounding sphere: R^mu only,
//     read as both maps (R^rho would be its copy);
//   - no bounce pass at the levels without bounce slots (and none on a frame after one without
//     VPLs: the bounce reads the previous frame's);
//   - the maps, VPLs and ISMs are reused, none drawn, sampled or splatted, while the level, the
//     camera pose, the depth frame and the lamps stay within gi/input_reuse.h's
//     tolerances of the frame that made them (the virtual objects are static: their pose joins
//     the comparison with dynamic scenes); a reused frame stays within 4/255 of the recomputed
//     one at 1.8 mm of depth change (tests/technique/dir_test.cpp: 3/255 measured); with bounce
//     slots only once the bounce has run kBounceGenerations frames on still inputs (each adds
//     one bounce), so a still scene keeps its multiple bounces.
// The ISMs' virtual maps are splatted whenever the maps are made: a virtual object outside every
// lamp's cone still blocks the bounce between real surfaces, which only its ISM shows.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "technique/technique.h"

namespace mrgi::technique {

struct DirLevel {
  const char* name;
  uint32_t vpls;            // VPL slots shaded
  uint32_t bounce_vpls;     // of them, the bounce light source's (0: one bounce)
  uint32_t env_vpls;        // of them, at most this many environment regions' (directional)
  // VPLs each of those regions is drawn as (a power of two, at most interleave^2): its light
  // split into equal-energy parts over its extent (light::EnvSampler::split_light), each part
  // shading one of that many classes of the interleaving block with the light of all (the merge
  // averages them), so a broad region casts a soft shadow at the cost of one VPL a pixel.
  uint32_t env_parts;
  uint32_t ism_size;        // texels per side of each VPL's imperfect shadow maps
  uint32_t points_per_vpl;  // points splatted into each of a VPL's two maps
  uint32_t rsm_size;        // texels per side of each reflective shadow map
  uint32_t rsm_lamps;       // lamps (strongest first) whose maps spawn VPLs; the slots split evenly
  uint32_t interleave;      // side of the interleaving block (4: 4x4, 1: every pixel every VPL)
  uint32_t indirect_divisor;  // G-buffer pixels per side of an indirect-light texel (1, 2, 4)
  float internal_scale;     // fraction of the output width and height
  float mesh_error_px;      // QualityLevel::mesh_error_px: the virtual G-buffer's level of detail
  int shadowed_env;         // environment regions the direct-light block shadows with maps (-1: its level's)
  int baseline_level;       // the direct-light block's level for the direct light
  // Virtual pixels take the bounce of the real-path VPLs (real surfaces lit by real lamps) also
  // where the light stage's ambient already holds that light below the horizon (light::Lighting::
  // ambient_below_from_camera: an env camera's unseen lower hemisphere lit by the colour camera's
  // mean radiance): the paper's. false: there they take the ambient's, not the VPLs' too. Why:
  // both are the real surfaces' light (spot_in_fisheye, a white box under a spot: high level
  // all-pixel RDE 0.345 with both, 0.205 without the VPLs'). Under the lamps' residual estimate
  // the VPLs' local bounce is kept (without it desk_spot 0.124 -> 0.168: a 1-3 band fit over the
  // frame does not hold it).
  bool real_bounce_beside_camera_ambient;
  float compose_tolerance;  // QualityLevel::compose_tolerance: 8-bit levels a kept tile may miss
};
const std::array<DirLevel, 5>& dir_levels();  // the defaults

// The regions of the light stage's environment cut (`regions` of them, strongest first) that
// get environment VPLs: every one but the first `mapped` of `shadowed` (the regions drawn as
// shadowed lights, light::LightStage::shadowed_environment_regions, whose shadow maps the
// direct-light block draws: they lie anywhere in the cut), in the cut's order, at most `most`.
// Written to out[0, n); n returned.
uint32_t environment_vpl_regions(size_t regions, const std::vector<size_t>& shadowed, size_t mapped, uint32_t most,
                                 uint32_t* out);
// The defaults with RuntimeSettings::knobs applied (technique/knobs.h; BadUsage for a refused one).
Expected<std::vector<DirLevel>> dir_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> dir_ladder(const std::vector<KnobSetting>& knobs);
Expected<std::unique_ptr<Technique>> create_dir(const frame::FrameResources& shared, const TechniqueOptions& options);

}  // namespace mrgi::technique
