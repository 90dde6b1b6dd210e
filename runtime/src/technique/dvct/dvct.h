// The `dvct` technique: Delta Voxel Cone Tracing (Thoener & Kuijper, "Delta global illumination
// for mixed reality", ../shared/papers/delta-voxel-cone-tracing.md). Four volumes over the
// region of Sec. 3.4 (the virtual objects' bounding box doubled, gi/voxelize.h
// doubled_box_region): the light volume (reflective shadow maps with the objects, +1), the delta
// light volume (the pair: with the objects +1, without -1, negative light allowed), and one
// visibility volume each for the real scene (the reconstruction's G-buffer as a surface, and the
// scene's proxy meshes) and for the virtual objects (their meshes), all with mip chains
// (gi/voxel_light.h, gi/voxelize.h). Pixels gather light through cones
// (shaders/gi/vct_trace.glsl, math in shaders/shared/vct_math.h): a diffuse set over the
// hemisphere, one specular cone whose aperture follows roughness, one shadow cone per lamp.
//
// Quality ladder (best first; DvctLevel below, with units):
//   level    volume  diffuse  specular  RSM    lamps  traced at   internal  direct light
//   paper    128^3   9        yes       512^2  4      every px    1.0       shadow cones (Sec. 3.5)
//   high      64^3   9        yes       512^2  4      1 in 2x2    1.0       baseline high's maps
//   medium    64^3   5        yes       256^2  2      1 in 4x4    1.0       baseline medium's
//   fast      16^3   3        no         64^2  1      1 in 4x4    0.5       baseline lowest's
//   fastest   16^3   1        no         64^2  1      1 in 4x4    0.5       baseline lowest's
// fast and fastest draw the virtual G-buffer at the meshes' level of detail within 0.2 internal
// pixels, as baseline lowest does (mesh_error_px).
// "paper" shades every pixel with cones alone (shaders/dvct/shade.comp). The others trace the
// cones at one pixel in a block (shaders/dvct/indirect.comp) into dir's packed indirect image,
// which the direct-light block's shading pass up-samples by surface and adds as it lights the pixel with
// shadow maps (the reduced-resolution shading with geometry-aware up-sampling of the fast path;
// the shadow maps are sharper than a 64^3 volume's shadow cones and cost less on a CPU device).
//
// Where mrgi differs from the paper and why:
//   - real pixels take with - without: the light volume through both visibility volumes minus
//     (light - delta) through the scene's alone (vct_trace.glsl says why: it also holds the scene
//     light the objects hide from the pixel, and their reflection in a real glossy surface);
//   - the accumulation is the emission-absorption form of Crassin et al., not the printed one
//     (vct_math.h vct_accumulate, tested), and the cones step at half the touching footprints
//     with opacity correction (vct_step: the paper's step aliases on one-voxel surfaces, measured
//     in tests/gi/test_vct_trace.cpp);
//   - the ambient (the light stage's SH: the residual estimate, or an environment's light beyond
//     its lamps) lights every pixel unshadowed, as in baseline; the paper has no such term (its
//     environment is injected only as the lamps its RSMs see). Shading it by the diffuse cones
//     (each cone's ambient radiance times its transmittance with the objects minus without)
//     made RDE worse on every suite scene it was measured on, at the high level (corner
//     real 0.885 -> 1.026, env_fisheye virtual 0.291 -> 0.437, moving real 0.410 ->
//     0.461, desk_spot equal): the cones over-occlude near a surface (its own voxels at coarse
//     mip levels, and vct_directional_occlusion's coverage rule, which treats a compact object
//     as a wall across the footprint), so the cones do not occlude the ambient: at every level
//     that is the direct-light block's environment occlusion (shading/environment_occlusion.h;
//     the paper level's shading reads it through DirectLightBlock::record_env_occlusion).
//   - the specular cone sees the objects with their own light and the environment as it is in
//     that direction: the objects' surfaces lit by the ambient, and their emission, are injected
//     into a fifth volume only that cone reads (object_light, gi::VoxelLight::add_inject_surfaces;
//     the paper injects lamp light only, so under an environment alone a glossy floor reflected
//     the objects black), and where the cone leaves the region it takes the light stage's
//     environment grid averaged over its width (common/env_grid.glsl), not the ambient's
//     irradiance over pi, which at a floor's glancing reflection takes in the bright sky above
//     the horizon the reflection looks at. The diffuse cones do not read the fifth volume: the
//     direct-light block's environment occlusion already gives back the objects' ambient-lit
//     surfaces to the real pixels near them.
//
// Skips (each in FrameStats::skipped):
//   - no virtual object: no volumes, no cones (the solutions are baseline's, or the paper
//     level's lamps and ambient unshadowed by any object);
//   - the volumes are reused, with nothing voxelised, drawn or injected, while what made them
//     stays within gi/input_reuse.h's tolerances (pose, depth, lamps, objects);
//   - the objects' own light volume is injected only in frames that trace the specular cone, once
//     per rebuild of the volumes;
//   - the objects' visibility volume is kept while they have not moved (frame::SceneGpu::revision) at
//     the same level: it depends on nothing else (1.5 ms a frame at fast on desk_spot's bunny);
//   - the reconstruction is voxelised from a grid of about two points a voxel where the region
//     is nearest the camera (Voxelizer::add_depth_surface's stride), not from every pixel;
//   - no specular cone at levels without it, or with no glossy material in view (virtual:
//     frame::SceneGpu::glossy and the objects' box in the camera's frustum; real: a scene.json
//     real_materials region with roughness under 0.7 or metallic over 0.1 whose box is): the
//     shading pass's variant without it runs (compiled out, not branched around), and the frame
//     is the same bit for bit (tests/technique/dvct_test.cpp); pixels rougher than that trace
//     none either way.
//
// Real materials: scene.json's real_materials regions (mrgi/scene.h RealMaterialRegion) give the
// real pixels inside them a roughness and metallic (the colour stays the camera's estimate); a
// glossy real surface then traces the specular cone too, with and without the objects, so it
// reflects them (and their shadow) and loses the reflection of what they hide. `mrgi synth`
// writes a region for every glossy or mirror real shape it renders.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "technique/technique.h"

namespace mrgi::technique {

struct DvctLevel {
  const char* name;
  uint32_t volume_cells;   // voxels per side of each of the four volumes
  uint32_t diffuse_cones;  // cones in the diffuse set (vct_math.h vct_diffuse_cone)
  bool specular_cone;      // one specular cone at glossy pixels
  uint32_t rsm_size;       // texels per side of each reflective shadow map
  uint32_t rsm_lamps;      // real lamps (strongest first) injected through a map pair
  uint32_t trace_divisor;  // G-buffer pixels per traced pixel, each side (1: every pixel); a
                           // level with shadow cones traces every pixel whatever this says
  float internal_scale;    // fraction of the output width and height
  // true: the paper's shading, direct light through shadow cones at every pixel
  // (shaders/dvct/shade.comp); false: baseline's shadow-mapped direct light at baseline_level,
  // the cones' light added in its shading pass.
  bool shadow_cones;
  int baseline_level;
  float shadow_aperture;   // full aperture of a shadow cone, radians (the penumbra's spread)
  float step_scale;        // fraction of the touching-footprint step the cones take (vct_step)
  // true: the objects' own light (their surfaces lit by the ambient, and their emission) is
  // injected into a volume the specular cone reads, so a glossy real surface reflects an object
  // under environment light as lit, not black (the light volume holds the lamps' maps only).
  bool object_light;
  float mesh_error_px;     // QualityLevel::mesh_error_px: the virtual G-buffer's level of detail (baseline lowest's at fast)
  float compose_tolerance; // QualityLevel::compose_tolerance: 8-bit levels a kept tile may miss
};
const std::array<DvctLevel, 5>& dvct_levels();  // the defaults
Expected<std::vector<DvctLevel>> dvct_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> dvct_ladder(const std::vector<KnobSetting>& knobs);
Expected<std::unique_ptr<Technique>> create_dvct(const frame::FrameResources& shared, const TechniqueOptions& options);

}  // namespace mrgi::technique
