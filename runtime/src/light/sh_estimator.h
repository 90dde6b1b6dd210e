// Probeless light estimation of the ssrt technique (paper Sec. 5.2, after Gruber et al. 2012):
// per pixel, the radiance transfer vector T(x) (SH, visibility included) and the camera's linear
// intensity I_c(x) give one row of T l = I_c; the estimated environment light l (SH) is the
// least-squares solution. The GPU sums the normal equations (T^T T, T^T I_c) over the frame; this
// class solves them with Eigen, regularised and filtered over time, and exports the result.
//
// Why regularised: the system is ill-posed whenever the frame does not show enough different
// normals (one flat wall: rank 1 without occlusion) or shows no light at all (a black couch:
// T^T T ~ 0 after the albedo), and band 3 is never constrained by unshadowed diffuse surfaces
// (its clamped-cosine factor is 0). Plain least squares then returns arbitrary or infinite
// coefficients. We solve
//     min_l ||T l - I_c / a||^2 + lambda * sum_i gamma_i (l_i - p_i)^2
// (Tikhonov towards p = the previous estimate, or the prior before the first one), so
// unconstrained directions keep what was known and constrained ones follow the data.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mrgi/expected.h"
#include "mrgi/light_estimate.h"
#include "light/sh_tools.h"

namespace mrgi::light {

// The frame's normal equations. `ata` is the full symmetric 16x16 matrix (row-major), `atb` is
// 16 x 3 (row-major: coefficient, then R G B). `samples` counts the rows (pixels) summed.
struct LightSystem {
  std::array<double, kMaxShCoeffs * kMaxShCoeffs> ata{};
  std::array<double, kMaxShCoeffs * 3> atb{};
  double samples = 0.0;

  // The band-1 block (coefficients 1..3) of the rows added by add_view, T^T T (3 x 3, row-major)
  // and T^T I_c (coefficient, then R G B): taken out again where the dominant real surface is
  // read from the system (a view of the light is no surface normal).
  std::array<double, 9> view_ata1{};
  std::array<double, 9> view_atb1{};

  void clear() { *this = LightSystem{}; }
  // Adds one pixel: transfer vector (the first `bands`^2 entries are used) and linear RGB.
  void add(const ShVector& transfer, const glm::dvec3& intensity);
  // Adds a row that is a view of the light itself (Y(w) . l = I_c), not a surface lit by it.
  void add_view(const ShVector& basis, const glm::dvec3& intensity);
};

struct LightEstimatorSettings {
  int bands = 4;                     // 1..4 SH bands solved (16 coefficients at 4)
  // Gray-world albedo assumed for every real surface (paper Sec. 6.4: the material colour is
  // not modelled, light is assumed white). The estimate scales with 1/this.
  double gray_albedo = 0.5;
  // Tikhonov weight relative to the mean diagonal of T^T T (dimensionless), so the balance of
  // data and prior does not depend on the number of pixels or on exposure. 1e-2 keeps the
  // directions that only the sampling noise of the jittered transfer spans (a few per cent of
  // |T|, i.e. eigenvalues ~1e-3 of the largest) from being fitted.
  double relative_regularisation = 1e-2;
  // Absolute floor of the weight (in units of T^T T), so a frame without any data (all black,
  // no valid pixel) returns the previous estimate instead of dividing by zero.
  double min_regularisation = 1e-9;
  // Per-band growth of the penalty: gamma_l = 1 + band_penalty * l (l + 1). Higher bands are
  // the ones least constrained by diffuse reflection (Ramamoorthi & Hanrahan 2001). Default 0:
  // on env_fisheye a growing penalty shrank the sun's band-2 lobe, and the estimate's RDE rose
  // from 0.586 to 0.602 (fast level).
  double band_penalty = 0.0;
  // Weight (relative to the mean diagonal of T^T T, like relative_regularisation) of the prior
  // that no light arrives from behind the frame's dominant real surface (a floor, a table, a
  // wall): the penalty mu * integral over that hemisphere of (sum_i l_i Y_i(w))^2 dw. Why: the
  // camera sees only surfaces that face it, so light from behind the dominant surface is
  // unconstrained, and with plain Tikhonov the estimate fills that hemisphere with about as
  // much light as the visible one; the dominant direction (band 1) then tilts towards the
  // horizon (env_fisheye: 68 degrees off, 10 with this prior). An opaque surface blocks that
  // light for everything in front of it, so the prior costs nothing where it is right. The
  // dominant surface's normal is the principal axis of the band-1 block of T^T T (the normals
  // the pixels have), signed by T^T I_c. 0 disables; needs bands >= 2. Every level solves 4
  // bands. With 2 bands a dark hemisphere beside a lit one can only be a strong band 1, and this
  // weight makes the visible side too directional (env_fisheye fastest with 2 bands, RDE and
  // direction error: 0.3 -> 0.707, 7 degrees; 0.02 -> 0.611, 45; 0 -> 0.602, 76): a 2-band
  // level would want about 0.02.
  double below_surface_penalty = 0.3;
  // Exponential temporal filter in frames: a solve covering the frames since the previous one
  // (a step of k frames by frame index) moves the estimate a fraction 1 - exp(-k / lag_frames)
  // towards its solution, so a step change of the light is followed with a time constant of
  // lag_frames frames (15: half a second at 30 fps), whatever the solves' spacing. Frame
  // indices, not timestamps: replays of stills and broken clocks cannot freeze or jump it.
  // 0 disables filtering.
  double lag_frames = 15.0;
  // The paper assumes white light (Sec. 5): the three channels are solved as one (luminance)
  // and exported grey. false: each channel is solved on its own (same T^T T).
  bool white_light = true;
  // The prior before the first frame: a uniform (band 0 only) environment of this radiance.
  double prior_radiance = 0.5;
  // Re-fit the prior's band 0 (ambient) to each frame before the regularised solve, so the
  // frame's overall brightness is not pushed into directional bands the data does not constrain
  // (a floor darker than the prior otherwise reads as light from below). false: plain Tikhonov.
  bool refit_prior_ambient = true;
  // Weight (relative to the mean diagonal of T^T T) of the penalty on negative radiance: after
  // the solve, the directions where the estimate's luminance is below 0 get the penalty
  // mu * integral over them of (sum_i l_i Y_i(w))^2 dw and the system is solved again, up to
  // `nonnegative_rounds` times. 0 disables.
  double nonnegative_penalty = 0.0;
  int nonnegative_rounds = 3;
  // Eigenvalues of T^T T above this fraction of the largest count as constrained (confidence).
  double confidence_eigen_fraction = 1e-2;
};

class LightEstimator {
 public:
  // BadUsage naming the field when a setting is out of range.
  static Expected<LightEstimator> create(const LightEstimatorSettings& settings);

  // Solves the frame's system, filters it into the running estimate and returns that. A system
  // holding NaN or Inf is refused (BadInput) and the estimate is kept as it was, so a broken
  // frame cannot poison the filter.
  // `solve_bands` (1..settings.bands, 0 = settings.bands) is the number of bands the frame's
  // transfer held (a quality level may use fewer); higher coefficients are solved as 0.
  Expected<LightEstimate> update(const LightSystem& system, int64_t frame_index,
                                 double timestamp_s, int solve_bands = 0);

  // The last frame's unfiltered least-squares solution and the filtered estimate.
  const ShRgb& frame_solution() const { return frame_solution_; }
  const ShRgb& filtered() const { return filtered_; }
  const LightEstimate& estimate() const { return estimate_; }
  const LightEstimatorSettings& settings() const { return settings_; }
  // The real surfaces' albedo per channel the rows are divided by (T l = I_c / a): the setting's
  // gray_albedo until a caller that has measured it (albedo_fit.h) sets it; each in (0, 1].
  void set_albedo(const glm::dvec3& albedo);
  const glm::dvec3& albedo() const { return albedo_; }
  // The last frame's dominant surface normal (world), used by below_surface_penalty; 0 when the
  // frame had none (no data or bands < 2).
  const glm::dvec3& dominant_normal() const { return dominant_normal_; }
  void reset();
  // The next `updates` updates replace the filtered estimate with their solutions (as the first
  // one does), keeping the estimate valid meanwhile: after a detected change of the light, while
  // the new light's view is still being gathered (its first solve may hold part of a view).
  void restart_filter(int updates = 1) {
    have_previous_ = false;
    replace_updates_ = std::max(updates, 1);
  }

 private:
  explicit LightEstimator(const LightEstimatorSettings& settings)
      : settings_(settings), albedo_(settings.gray_albedo) {}

  LightEstimatorSettings settings_;
  glm::dvec3 albedo_;
  ShRgb frame_solution_{};
  ShRgb filtered_{};
  LightEstimate estimate_;
  glm::dvec3 dominant_normal_{0.0};
  bool have_previous_ = false;
  int replace_updates_ = 0;  // restart_filter's updates still to replace outright
  int64_t last_frame_ = 0;
};

}  // namespace mrgi::light
