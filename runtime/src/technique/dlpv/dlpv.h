// The `dlpv` technique: Delta Light Propagation Volumes (Franke 2013,
// ../shared/papers/delta-light-propagation-volumes.md). Per real lamp of the light stage, a
// reflective shadow map pair (gi/rsm.h: with and without the virtual objects) is injected into
// one volume centred on the virtual objects as +R^rho - R^mu, VPLs (eq. 12-13) and direct light
// (Sec. 4.3.2, the antiradiance that shadows), propagated (gi/light_propagation.h), and merged
// as Algorithm 1 (shaders/dlpv/merge.comp). The best levels also propagate V^rho (R^rho alone)
// for the virtual pixels' bounce light: the paper level always, high and medium only where the
// light stage's ambient does not already hold the real scene's bounce (an environment image
// file's ambient); elsewhere their virtual pixels take that ambient (rho_beside_bounce_ambient).
//
// Quality ladder (best first; DlpvLevel below, with units):
//   level    volume  steps  RSM    RSM lamps  V^rho  internal scale  shadows
//   paper    32^3    32     512^2  4          yes    1.0             antiradiance (Algorithm 1)
//   high     32^3    32     512^2  4          (1)    1.0             baseline high's shadow maps
//   medium   16^3    16     256^2  2          (1)    1.0             baseline medium's
//   fast      8^3     8     128^2  1          no     0.5             baseline lowest's (the reduced-volume fast path)
//   fastest   8^3     4      64^2  1          no     0.5             baseline lowest's
// (1) where the ambient is an environment image file's (rho_beside_bounce_ambient).
// fast and fastest draw the virtual G-buffer at the meshes' level of detail within 0.2 internal
// pixels, as baseline lowest does (mesh_error_px).
// "paper" is the published method with its settings (Sec. 5); the others keep its volume and
// light the scene directly with shadow maps (Sec. 7's alternative), because the antiradiance
// shadow is coarse (a 32^3 volume over twice the object) and cut off where the volume ends.
// Those levels record the direct-light block after the volumes, and its shading pass adds the
// volumes' bounce light as it shades each pixel (shading/direct_light.comp, its volume input): a pass of its own cost its G-buffer reads and L_rv's read-modify-write.
//
// Where mrgi differs from the paper and why:
//   - the propagation gathers with exact face solid angles and damps negative flux by the
//     directional derivative along the propagation (shaders/shared/lpv_math.h says how); the
//     paper names the cue, not the formula;
//   - VPLs are summed with float atomics in a compute pass, not as points blended into slices
//     (lavapipe rasterises points on one thread; the sums are the same);
//   - real albedo is recon's per-pixel estimate (camera colour over the modelled light), the
//     paper's eq. 1;
//   - lamps beyond the level's RSM count still light directly (unshadowed), without bounce.
//   - R^rho is drawn as R^mu's copy with the virtual objects drawn over it (gi/rsm.h add_pair),
//     and V^Delta is injected from the texels where the two maps differ only, both maps in one
//     pass: the same maps and the same sum (the other texels cancel exactly), for the real
//     casters drawn once and a fraction of the injection's work.
//
// Against the paper author's code (thefranke/dirtchamber, D3D11, MIT; read, not copied):
//   - it propagates in a pixel shader over 2D texture-array slices with Kaplanyan's two
//     constant face solid angles and a user "flux amplifier"; mrgi gathers in a compute shader
//     with exact face solid angles and no amplifier, so the transport is physically scaled and
//     needs no per-scene constant (what generalises to scenes nobody tuned for);
//   - its delta propagation carries signed values with no damping (the threshold that would
//     zero small values is commented out for its 2 ms); mrgi damps negative flux by the
//     directional derivative (paper Sec. 4.4) and measures what that is worth
//     (perf/results/dlpv/ablation: without it, V^Delta equals two volumes subtracted);
//   - it splats VPLs as points into slices with additive blending; mrgi sums them with float
//     atomics (lavapipe rasterises points on one thread), and runs every propagation step of a
//     volume of at most 8^3 in one workgroup (a dispatch a step costs more than the step on a
//     CPU device);
//   - the same half-cell shift along the normal, the same rejection of VPLs facing away, and the
//     same signed (dscale) injection of the two maps.
//
// Skips (each in FrameStats::skipped):
//   - no virtual object, or no real lamp a map can see the volume from: no maps, no volumes;
//   - the volumes are reused, with no map drawn, injected or propagated, while what made them
//     stays within tolerance: the same level; the camera pose within 1 mm and 0.1 degrees;
//     the depth frame within 2 mm mean absolute change over pixels valid in both, with at most
//     0.5 % of pixels gaining or losing a depth; every mapped lamp within 1 mm, 0.5 degrees
//     and 1 % of its colour. (The reconstruction is a function of depth and pose, so the real
//     grid the maps draw moves by about the depth change.) A reused frame stays within 4/255
//     per channel of the recomputed one (tests/technique/dlpv_test.cpp: 3/255 measured at 1.8 mm).
//     The comparison is gi/input_reuse.h, shared with dir.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "technique/technique.h"

namespace mrgi::technique {

struct DlpvLevel {
  const char* name;
  uint32_t volume_cells;   // cells per side of each volume
  uint32_t steps;          // propagation steps
  uint32_t rsm_size;       // texels per side of each reflective shadow map
  uint32_t rsm_lamps;      // real lamps (strongest first) with a map pair; others light directly
  bool rho_volume;         // V^rho for the virtual pixels' bounce light
  float internal_scale;    // fraction of the output width and height
  // true: the paper's Algorithm 1, shadows as the volume's antiradiance (blocked direct light
  // injected). false: direct light with the direct-light block's shadow maps (this baseline level), the volume
  // carrying the bounce light's change only (the paper's Sec. 7 alternative).
  bool antiradiance_shadows;
  int baseline_level;      // the direct-light block's level for the shadow maps (when not antiradiance)
  // V^rho (with rho_volume) on virtual pixels also where the light stage's ambient already holds
  // the real scene's bounce (light::Lighting::ambient_holds_real_bounce: the lamps' residual
  // estimate, an env camera's unseen lower hemisphere lit by the colour camera's mean radiance,
  // the probeless estimate): the paper's. false: there the virtual pixels take that ambient, as
  // baseline's do, and V^rho is not propagated; it is kept where the ambient is an environment
  // image's, which knows nothing of the real surfaces round the object. Why: V^rho added to
  // such an ambient counts the bounce twice, and in its place it loses the room's further
  // bounces, while the volume, which does not block its own light, lets a convex object's lit
  // face light the object's other faces (spot_in_fisheye, a white box under a spot: virtual-pixel
  // RDE 0.68 with V^rho, 0.17 with the ambient; corner 0.43 / 0.29; desk_spot 0.35 / 0.19).
  bool rho_beside_bounce_ambient;
  float mesh_error_px;     // QualityLevel::mesh_error_px: the virtual G-buffer's level of detail (baseline lowest's at fast)
  float compose_tolerance; // QualityLevel::compose_tolerance: 8-bit levels a kept tile may miss
};
const std::array<DlpvLevel, 5>& dlpv_levels();  // the defaults
// The defaults with RuntimeSettings::knobs applied (technique/knobs.h; BadUsage for a refused one).
Expected<std::vector<DlpvLevel>> dlpv_levels(const std::vector<KnobSetting>& knobs);
Expected<std::vector<QualityLevel>> dlpv_ladder(const std::vector<KnobSetting>& knobs);
Expected<std::unique_ptr<Technique>> create_dlpv(const frame::FrameResources& shared, const TechniqueOptions& options);

}  // namespace mrgi::technique
