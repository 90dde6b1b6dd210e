// The `ssrt` technique: image-space radiance transfer with probeless SH light estimation
// ("Image-Space Illumination for Augmented Reality in Dynamic Environments", Sec. 5).
//
// Per frame (passes in order, after the geometry stage below and the virtual G-buffer):
//   ssrt_occluders           what the transfer's samples read where they land (virtual
//                            surface, real and virtual albedo) gathered once per texel of the
//                            occluder grid (knob occluder_step; occluders.comp says why)
//   ssrt_transfer            SSDO visibility of N jittered directions (2x2 sets) per cell of the
//                            sub-sampled grid, projected to SH (eq. 6-9), real and real+virtual
//                            in one pass, with one-bounce indirect light (eq. 10-12); cells
//                            outside the virtual objects' projected bounds take a path that
//                            shares every lookup between both solutions
//   ssrt_light_reduce(+final) the normal equations of T l = I_c summed on the GPU; the host
//                            reads them back frames_in_flight frames later (no stall) and solves
//                            them (light_estimator.h), the result lights the next frames
//   ssrt_upsample_blur       fast levels only: Gauss radius 8 px over the coarse grid, packed
//                            to one RGBA32UI texel per cell (upsampled.glsl)
//   ssrt_shade               bicubic up-sampling, writes L_r and L_rv for the runtime's compose;
//                            at subsample > 1: ssrt_shade_tiles lists the 8x8 tiles whose result
//                            can differ from the camera, ssrt_shade_tiled shades only those
//                            (indirect dispatch) and hands them to compose (compose_tiles),
//                            which copies the camera frame elsewhere; at the camera's size
//                            ssrt_shade_tiled writes those tiles' composite itself (shade.comp
//                            kCompose, the runtime's formula) and compose runs no pass
// Skips: no virtual object in the scene, or its bounds grown by the occluder range (its
// influence region, 2 x the 0.5 m sampling radius) outside the view: the transfer passes do not
// run and L_rv = L_r = camera colour (compose then returns the camera image unchanged); the
// light estimate is kept. Inside a frame, cells outside the influence region's screen rectangle
// copy the real solution instead of computing the real + virtual one (bit-identical, by the
// range check), and pixels outside it are written as pass-through.
//
// Quality ladder (best first), knobs with units:
//   level  name     subsample  directions  sh_bands  internal_scale  geometry_step  occluder_step
//   0      full     1          64          4         1.0             1              1 ("Ours")
//   1      half     2          32          4         1.0             1              1
//   2      fast     4          32          4         1.0             4              4 ("OursFast")
//   3      fastest  4          16          4         0.5             2              1
// subsample: cells are step x step pixels; directions: N per jitter set; sh_bands: SH bands of
// the transfer and of the estimated light; geometry_step: internal pixels per texel side of the
// volume ray cast, the depth filters (windows shrunk to match) and their G-buffer, which the
// transfer reads at its cell centres (occluder lookups through the texel's tangent plane);
// occluder_step: internal pixels per texel side of the occluder G-buffer (at 320x240 internal
// the fastest level keeps it per pixel: 2x2 texels lost thin virtual parts' contact shadows in
// the 64x48 unit test, and its full-resolution images are small enough to stay in cache).
//
// Deviations from the paper, each explained where it is implemented: chi of eq. 9 read as a
// one-minus-cosine threshold and G of eq. 12 on the sender's normal (transfer_math.h); F of eq. 11
// with the SSDO patch area and a distance clamp; a range check (2 x radius) on occluders; light
// in radiance units (1/pi in the transfer); the up-sampling filters do not mix real and virtual
// cells; the composite is the runtime's ratio form rather than eq. 13's tone-mapped difference
// (shade.comp; eq. 13-14 themselves are in transfer_math.h and tested); indirect light comes from
// the main G-buffer only.
//
// Geometry (paper Sec. 4, run first every frame): ssrt::Volume (volume.h) fuses the raw depth
// into a TSDF cube of 2 m centred on the virtual objects (256^3 at full/half, 64^3 at
// fast/fastest), ray-casts D_v for the view and four auxiliary orthographic layers (left, right,
// top, dominant light); ssrt::DepthFilterGpu (depth_filter_gpu.h) runs D', D'' and (full/half)
// D''' and writes the G-buffer the transfer and shade read. A sample the view finds free is
// also tested against the aux layers (visibility only: an aux occluder sends no indirect light,
// its colour and normal are unknown). The runtime's reconstruction (recon/) does not run for
// ssrt: the camera colour (I_c) is read from the upload where it is used, and the virtual
// objects' depth test reads this G-buffer (Technique::occlusion_geometry; at geometry step > 1
// through each texel's tangent plane).
//
// Light estimate on the suite's environment-lit scene (perf/suite/env_fisheye, 8 frames, truth:
// band 1 of each frame's environment image; test GoldenSsrt): direction error median / worst
// and pooled RDE (baseline, which reads the environment image itself: 0.629):
//   full 16.4 / 16.8 degrees, RDE 0.568;  half 7.4 / 7.6, 0.564;  fast 7.9 / 8.1, 0.561;
//   fastest 5.2 / 5.4, 0.619.
// What makes it work: only pixels the camera measured and whose green is unclipped feed the
// sums (transfer.comp), a prior that no light comes from behind the dominant surface
// (LightEstimatorSettings::below_surface_penalty), and the first frame primed from itself
// (Technique::estimate_pending). With the environment's true SH in place of the estimate the
// fast level scores RDE 0.563, so the estimate costs about 0.02. Every level, fastest included,
// uses 4 SH bands: the transfer accumulates all 16 coefficients whatever the level, so 2 bands
// would save nothing and cost the direction (46 degrees off; LightEstimatorSettings::
// below_surface_penalty says why).
//
// Cost on lavapipe (LP_NUM_THREADS=2, 640x480, `mrgi bench --techniques ssrt`;
// perf/results/report-ssrt-640x480.md (4 frames after 1) and report-ssrt-fast-16frames.md;
// floor 1.6-2.8 ms): suite mean sustained full 823 ms, half 480, fast 42.8, fastest 40.0; fast
// over the scenes with a virtual object 20.0 floors (median; 17.3-21.9 over two runs, 21.3 in
// a third), against about 22 for 33 ms on a 1.5 ms floor. Fast level split
// (profiling mode, ratio to the floor): transfer 5.9 floors, shade (composing its tiles) 2.1 and
// its tile test 0.45, host 1.3, ray cast 1.3, blur 0.95, filters 0.9, virtual G-buffer 0.8,
// occluders 0.75, fuse 0.7, G-buffer 0.5, light sums 0.5, aux layers 0.3: about 17.5 floors
// profiled, 20 sustained.
// Why the passes are shaped as they are (fast level, measured against the alternative; A/B reports
// perf/results/ab-ssrt-fast-*.md): no runtime reconstruction (-14 ms); constant indices into the
// transfer's and the light sums' local arrays (a dynamic index puts them in per-lane scratch
// memory: -5 and -3 ms); compose fused into the tiled shade; the right aux layer mirrored from the
// left one's matrix (transfer -17 %); the blur's radius a specialization constant (blur -14 %);
// tiles that cannot move a pixel by one 8-bit level left to the camera frame (ssrt_tile_invisible:
// shaded tiles -29 %); aux layers at 32 texels on the fast levels (their ray cast -75 %);
// workgroups in spread order for lavapipe's static split of a dispatch between its workers. Two
// lavapipe rules, read from its JIT code (perf/tools/jit_probe.py): a uniform read after any branch
// is a per-lane gather, so uniform blocks are copied on each pass's first line (transfer 32 -> 18
// ms); a per-lane storage-buffer load is a branchy loop over the lanes, so the sample directions
// live in a uniform buffer and the camera uploads and voxels are read through texel buffers
// (transfer -22 %, ray cast -45 %, shade -20 %). Also for speed: the occluder G-buffer, mesh levels
// of detail and a bounded virtual G-buffer, one weighted (grouped) bicubic sum in shade, N_v
// culled, three aux lookups instead of four, the camera copy on the host, R'_d as weight x L(w) (16
// accumulators fewer), each sender normalised once, integer divisions through floats, the light
// sums' final pass on 8 workgroups.
// What the transfer's time is (knock-out runs, process CPU, desk_spot/corner): the real-receiver
// path is 87 % of it; the aux test 35 % (each layer about 7 ms of CPU; without its image loads
// only 10 % less, so it is the arithmetic and the registers it holds, not the reads); the SH
// basis 5 %; T_real's 16 accumulators 13 %. On lavapipe a shader's live values decide its cost:
// a per-lane choice between two uniform matrices cost 17 % of the pass.
// Known defects: the grey-world albedo (paper Sec. 6.4) reads brighter objects as more light
// from their side (env_fisheye's boxes and ball are 0.6-0.7, its floor 0.5); the fast level
// meets the 33 ms bar on lavapipe without margin (20-22 floor passes against about 22); its
// coarse geometry costs corner 0.017 RDE (0.748 -> 0.765; geometry_step 2 gives 0.741 but ~24
// ms more).
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "mrgi/light_estimate.h"
#include "technique/technique.h"

namespace mrgi::technique {

// One level of the ladder, typed (the generic QualityLevel knobs are made from it).
struct SsrtLevel {
  const char* name;
  uint32_t subsample;          // pixels per cell side (transfer computed once per cell)
  uint32_t directions;         // visibility directions per pixel (per 2x2 jitter set)
  uint32_t sh_bands;           // SH bands of transfer and estimated light
  float internal_scale;        // fraction of the output width and height
  uint32_t volume_resolution;  // TSDF voxels per side of the 2 m workspace cube
  uint32_t aux_resolution;     // texels per side of each auxiliary orthographic buffer
  bool final_filter;           // the third median pass (eq. 5)
  uint32_t geometry_step;      // internal pixels per texel side of the ray cast, filters, G-buffer
  uint32_t occluder_step;      // internal pixels per texel side of the occluder G-buffer
  // Projected error of the virtual meshes' level of detail, internal pixels (0 = full detail):
  // the fast levels draw within half an internal pixel (desk_spot fast: virtual G-buffer 8.5 ->
  // 4.3 ms, RDE 0.8280 -> 0.8283).
  float mesh_error_px;
};
const std::array<SsrtLevel, 4>& ssrt_levels();  // the defaults
// The defaults with RuntimeSettings::knobs applied (technique/knobs.h; BadUsage for a refused one).
Expected<std::vector<SsrtLevel>> ssrt_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> ssrt_ladder(const std::vector<KnobSetting>& knobs);
Expected<std::unique_ptr<Technique>> create_ssrt(const frame::FrameResources& shared, const TechniqueOptions& options);

}  // namespace mrgi::technique
