// The `ssrt` technique: image-space radiance transfer with probeless SH light estimation
// ("Image-Space Illumination for Augmented Reality in Dynamic Environments", Sec. 5).
//
// Per frame (passes in order):
//   ssrt_transfer            SSDO visibility of N jittered directions (2x2 sets) per cell of the
//                            sub-sampled grid, projected to SH (eq. 6-9), real and real+virtual
//                            in one pass, with one-bounce indirect light (eq. 10-12)
//   ssrt_light_reduce(+final) the normal equations of T l = I_c summed on the GPU; the host
//                            reads them back frames_in_flight frames later (no stall) and solves
//                            them (light_estimator.h), the result lights the next frames
//   ssrt_upsample_blur       fast levels only: Gauss radius 8 px over the coarse grid
//   ssrt_shade               bicubic up-sampling, writes L_r and L_rv for the runtime's compose
// Skips: no virtual object in the scene, or its bounds grown by the occluder range (its
// influence region, 2 x the 0.5 m sampling radius) outside the view: the transfer passes do not
// run and L_rv = L_r = camera colour (compose then returns the camera image unchanged); the
// light estimate is kept. Inside a frame, cells outside the influence region's screen rectangle
// copy the real solution instead of computing the real + virtual one (bit-identical, by the
// range check), and pixels outside it are written as pass-through.
//
// Quality ladder (best first), knobs with units:
//   level  name     subsample  directions  sh_bands  internal_scale
//   0      full     1          64          4         1.0   (paper "Ours")
//   1      half     2          32          4         1.0
//   2      fast     4          32          4         1.0   (paper "OursFast": 4x4, up-sampled)
//   3      fastest  4          16          4         0.5
// subsample: cells are step x step pixels; directions: N per jitter set; sh_bands: SH bands of
// the transfer and of the estimated light.
//
// Deviations from the paper, each explained where it is implemented: chi of eq. 9 read as a
// one-minus-cosine threshold and G of eq. 12 on the sender's normal (ssrt_math.h); F of eq. 11
// with the SSDO patch area and a distance clamp; a range check (2 x radius) on occluders; light
// in radiance units (1/pi in the transfer); the up-sampling filters do not mix real and virtual
// cells; the composite is the runtime's ratio form rather than eq. 13's tone-mapped difference
// (shade.comp; eq. 13-14 themselves are in ssrt_math.h and tested); indirect light comes from
// the main G-buffer only.
//
// Geometry (paper Sec. 4, run first every frame): ssrt::Volume (volume.h) fuses the raw depth
// into a TSDF cube of 2 m centred on the virtual objects (256^3 at full/half, 64^3 at
// fast/fastest), ray-casts D_v for the view and four auxiliary orthographic layers (left, right,
// top, dominant light); ssrt::DepthFilterGpu (depth_filter_gpu.h) runs D', D'' and (full/half)
// D''' and writes the G-buffer the transfer and shade read. A sample the view finds free is
// also tested against the aux layers (visibility only: an aux occluder sends no indirect light,
// its colour and normal are unknown). The runtime's recon G-buffer is used only for the camera
// colour (I_c) and the virtual objects' depth test.
//
// Light estimate on the suite's environment-lit scene (perf/suite/env_fisheye, 8 frames, truth:
// band 1 of each frame's environment image; test GoldenSsrt): direction error median / worst
// and pooled RDE (baseline, which reads the environment image itself: 0.629):
//   full 16.4 / 16.8 degrees, RDE 0.568;  half 7.4 / 7.6, 0.564;  fast 8.5 / 9.0, 0.583;
//   fastest 7.4 / 7.8, 0.618.
// What made it work (session 4): only pixels the camera measured and whose green is unclipped
// feed the sums (transfer.comp), a prior that no light comes from behind the dominant surface
// (LightEstimatorSettings::below_surface_penalty), and the first frame primed from itself
// (Technique::wants_priming_run). With the environment's true SH in place of the estimate the
// fast level scores RDE 0.563, so the estimate costs about 0.02.
//
// Known defects: the grey-world albedo (paper Sec. 6.4) reads brighter objects as more light
// from their side (env_fisheye's boxes and ball are 0.6-0.7, its floor 0.5); the fast level
// costs far more than 33 ms on lavapipe: 208 ms sustained, suite mean at 640x480 (session 5,
// `mrgi bench --techniques ssrt --frames 4 --warmup 1`), of which the profiled split gives the
// TSDF ray cast 68 ms and the transfer 80 ms, shade 34 ms; the ray cast and the volume's
// G-buffer still run per pixel of the internal resolution, not per transfer cell as the level
// allows. The fastest level had 2 SH bands until session 4; the transfer accumulates all 16
// coefficients whatever the level, so 2 bands saved nothing and cost the direction (46 degrees
// off; LightEstimatorSettings::below_surface_penalty says why).
#pragma once
#include <memory>
#include <vector>

#include "mrgi/light_estimate.h"
#include "technique/technique.h"

namespace mrgi::technique {

std::vector<QualityLevel> ssrt_ladder();
Expected<std::unique_ptr<Technique>> create_ssrt(const SharedResources& shared);
// The light estimate of an ssrt technique (nullptr when `t` is not one).
const LightEstimate* ssrt_light_estimate(const Technique& t);

}  // namespace mrgi::technique
