/// \file
/// The real-world light as the runtime's light stage knows it (declared lamps, an environment
/// image, or the probeless estimate from the camera frames), in the forms AR apps consume:
/// spherical-harmonics environment radiance and one dominant directional light, as LightEstimate;
/// ARCore Environmental HDR's shape (EnvironmentalHdr: main light, 27 SH coefficients, a small
/// HDR cubemap); and Filament's pre-scaled irradiance SH (to_filament_irradiance).
///
/// Conventions (docs/DESIGN.md): world space, right-handed, metres, +y up; linear RGB.
/// SH: real orthonormal basis of shaders/shared/mrgi_shared.h (Sloan 2008 sign convention and
/// index order l*(l+1)+m, m = -l..l). Radiance is L(w) = sum_i sh_radiance[i] * Y_i(w).
#pragma once
#include <array>
#include <cstdint>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi {

using Rgb = std::array<float, 3>;

struct LightEstimate {
  /// false until the first frame whose system was solvable; the fields below then hold the prior.
  bool valid = false;
  int64_t frame_index = -1;   ///< the frame whose image the estimate was solved from
  double timestamp = 0.0;     ///< that frame's timestamp, seconds
  int bands = 4;              ///< 1..4: coefficients beyond bands*bands are 0
  /// Environment radiance SH, linear RGB radiance (camera exposure divided out), up to 4 bands.
  std::array<Rgb, 16> sh_radiance{};
  /// The same light as irradiance SH (cosine-lobe convolved, Ramamoorthi & Hanrahan 2001: bands
  /// 0..2 times pi, 2pi/3, pi/4): E(n) = sum_i irradiance_sh9[i] * Y_i(n). Lambertian outgoing
  /// radiance of albedo a is a * E(n) / pi.
  std::array<Rgb, 9> irradiance_sh9{};
  /// Unit vector from the scene TOWARDS the dominant light (world space), from SH band 1 (paper
  /// Sec. 5.4). Filament's LightManager direction is the opposite (the direction light travels).
  std::array<float, 3> direction_to_light{0.0f, 1.0f, 0.0f};
  /// Irradiance at normal incidence of the directional light that best reproduces the directional
  /// (band >= 1) part of the estimated irradiance, linear RGB (>= 0).
  Rgb dominant_intensity{};
  /// How well the frame constrained the estimate, 0..1: the fraction of the 16 SH directions
  /// (eigenvalues of the normal matrix) the data constrained without help from the prior. A frame
  /// that sees one flat wall gives a low value; a room corner with floor and walls a higher one.
  float confidence = 0.0f;
};

/// The light of an environment image (linear radiance; equirectangular with the path tracer's
/// convention u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi, or an equidistant fisheye with
/// pixel centres at integer coordinates) in the form an estimate has: radiance SH projected
/// from every pixel by its solid angle (a fisheye contributes only the directions it sees),
/// then the dominant direction and intensity from band 1 exactly as for an estimate. This is
/// the ground truth an estimate is compared with. `intensity` scales the radiance. confidence is
/// 1, frame_index -1. BadInput for an empty image or a fisheye without a focal length.
MRGI_API Expected<LightEstimate> light_from_environment(const ImageRGBF& image, const EnvCamera& camera,
                                               double intensity = 1.0, int bands = 4);

/// ARCore Environmental HDR's shape (ArLightEstimate_getEnvironmentalHdr*): what an app written
/// against ARCore's light estimation reads, filled from a LightEstimate.
struct EnvironmentalHdr {
  /// Unit vector towards the main light, world space (ARCore's main light direction; Filament's
  /// LightManager::setDirection wants its negation: the direction light travels).
  std::array<float, 3> main_light_direction{0.0f, 1.0f, 0.0f};
  /// Its irradiance at normal incidence, linear RGB (ARCore's main light intensity).
  std::array<float, 3> main_light_intensity{0.0f, 0.0f, 0.0f};
  /// Ambient radiance SH, 9 RGB triplets (27 floats: coefficient-major, R G B), bands 0..2 of
  /// LightEstimate::sh_radiance: the real orthonormal basis with the Condon-Shortley sign, the
  /// same coefficients ARCore's getEnvironmentalHdrAmbientSphericalHarmonics returns (not
  /// convolved: multiply by to_filament_irradiance's factors for Filament).
  std::array<float, 27> ambient_sh{};
  /// The HDR cubemap (when asked for; else empty): 6 faces of face_size^2 linear RGB texels in
  /// OpenGL's order +X, -X, +Y, -Y, +Z, -Z and orientation (ARCore's 16 x 16 cubemap), the SH
  /// radiance evaluated at each texel's direction (so blurred to 4 bands), clamped at 0.
  int face_size = 0;
  std::array<ImageRGBF, 6> cubemap;
  bool valid = false;
};

/// The confidence (LightEstimate::confidence) from which to_environmental_hdr calls an estimate
/// valid: 3 of the 16 SH directions constrained by the data. Why: on the moving-camera light
/// family's tuning half (every frame of 4 sweeps, baseline high) the estimate-lit RDE over the
/// true-lit was 2.35 (median) at 1 / 16, 1.55 at 2 / 16 (worst 2.62), 1.26 at 3 / 16 and 1.17 at
/// 4 / 16 (perf/results/light-moving/README.md). A still camera on one flat surface stays below it;
/// an environment image's light has confidence 1. Across scenes it does not rank the error (the
/// still-camera family's two valid scenes had ratios of 2.0): it keeps a sweep's first frames out.
inline constexpr float kEnvironmentalHdrMinConfidence = 3.0f / 16.0f;

/// `valid` = the estimate's and its confidence at least `min_confidence` (0..1; 0 passes every
/// valid estimate). BadUsage for face_size outside 0..256 (0 = no cubemap) or min_confidence
/// outside 0..1.
MRGI_API Expected<EnvironmentalHdr> to_environmental_hdr(const LightEstimate& estimate, int face_size = 16,
                                                         float min_confidence = kEnvironmentalHdrMinConfidence);

/// Filament's irradiance SH (IndirectLight::Builder::irradiance(3, sh)): 9 RGB coefficients
/// pre-scaled by the cosine lobe A_l / pi and the basis constants, so that Filament's shader
///   `max(sh[0] + sh[1] y + sh[2] z + sh[3] x + sh[4] y x + sh[5] y z + sh[6] (3 z^2 - 1)`
///       `+ sh[7] z x + sh[8] (x^2 - y^2), 0)`
/// gives E(n) / pi, the Lambertian radiance of a white surface (Filament then multiplies by the
/// diffuse colour). The factors per coefficient are (A_l / pi) * K_lm * (Condon-Shortley sign):
/// 0.282095, -0.325735, 0.325735, -0.325735, 0.273137, -0.273137, 0.078848, -0.273137, 0.136569,
/// the same as Sceneform applies to ARCore's coefficients. Both use +y up, right-handed world
/// axes, so no rotation is needed.
MRGI_API std::array<Rgb, 9> to_filament_irradiance(const LightEstimate& estimate);

/// Angle in degrees between the dominant directions of two estimates.
MRGI_API double direction_error_deg(const LightEstimate& a, const LightEstimate& b);

/// Irradiance E(n) of an estimate for a unit normal n (world space), linear RGB.
MRGI_API Rgb irradiance_at(const LightEstimate& estimate, const std::array<float, 3>& normal);

}  // namespace mrgi
