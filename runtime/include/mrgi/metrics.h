/// \file
/// Error metrics shared by the runtime, the tests and the bench (docs/DESIGN.md "Ground truth and
/// error"). O = mrgi's output, C = the camera frame, G = the ground-truth augmented frame.
#pragma once
#include <cstddef>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/image.h"

namespace mrgi {

struct ErrorFigures {
  /// RDE = ||(O-C)-(G-C)|| / ||G-C|| over the set's pixels, in linear RGB (sRGB decoded):
  /// 0 is perfect, 1 is no better than leaving the camera frame untouched.
  double rde = 0.0;
  /// False when ||G-C|| is 0 over the set (nothing should change there, e.g. no virtual pixel):
  /// rde is then meaningless and reported as 0; delta_rms tells how much O changed anyway.
  bool rde_defined = false;
  double delta_rms = 0.0;  ///< RMS of (O-C)-(G-C) per channel, linear units (0..1)
  double rmse8 = 0.0;      ///< RMSE of O against G in 8-bit sRGB units
  double ssim = 1.0;       ///< mean SSIM of sRGB luma (Wang et al. 2004: 11x11 Gaussian, sigma 1.5)
  size_t pixels = 0;
  /// Sums behind rde, so figures over many frames pool as sqrt(sum err2 / sum ref2).
  double err2 = 0.0;       ///< sum over the set of |O-G|^2 (linear RGB)
  double ref2 = 0.0;       ///< sum over the set of |G-C|^2
  /// Signed sums over the set and the three channels of O-C and of G-C (linear RGB): how much
  /// light the output adds (> 0) or takes away (< 0) against how much the truth does, e.g. the
  /// darkening a virtual object's occlusion casts on the real pixels around it.
  double change_sum = 0.0, truth_change_sum = 0.0;
  /// The same per channel (R, G, B): "too strong", "wrong colour" and "missing" read directly
  /// (a mean change per pixel is the sum over `pixels`).
  double change_rgb[3] = {0.0, 0.0, 0.0}, truth_change_rgb[3] = {0.0, 0.0, 0.0};
};

struct RdeReport {
  ErrorFigures all, real, virtual_;  ///< virtual_: pixels where the mask is non-zero
  /// The real pixels split by the truth: `influenced` where the virtual objects change them
  /// (|G-C| in some channel above three 8-bit sRGB steps at C's level, three times the
  /// quantisation noise of the two images), `rest` the others (where the output should not
  /// change them).
  ErrorFigures influenced, rest;
  /// `influenced` split by the sign of the truth's change of luminance there: `darkened` where
  /// the virtual objects take light from the real scene (their shadows, their occlusion of the
  /// environment), `brightened` where they add light (bounce and colour bleeding, caustics,
  /// their reflection in real surfaces).
  ErrorFigures darkened, brightened;
  /// Pixels within kSilhouetteBandPx of the mask's edge, on either side: the virtual objects'
  /// silhouettes, where a level's internal resolution below the output's shows first (a blocky
  /// or haloed edge). Empty without a mask.
  ErrorFigures silhouette;
};

/// The silhouette band's half width, output pixels (Euclidean distance to a pixel of the other
/// side of the mask).
inline constexpr int kSilhouetteBandPx = 2;

/// virtual_mask: nullptr = every pixel is real; else one byte per pixel, non-zero = virtual.
/// Different sizes are a BadInput error naming the sizes.
MRGI_API Expected<RdeReport> measure_error(const ImageRGB8& output, const ImageRGB8& camera,
                                  const ImageRGB8& reference, const ImageU8* virtual_mask);
MRGI_API Expected<RdeReport> measure_error(const ImageRGBA8& output, const ImageRGB8& camera,
                                  const ImageRGB8& reference, const ImageU8* virtual_mask);

/// Pools figures of several frames (pixel-weighted means for rmse8/ssim, sums for rde).
MRGI_API ErrorFigures pool(const ErrorFigures& a, const ErrorFigures& b);
/// The same for each of a report's pixel sets.
MRGI_API RdeReport pool(const RdeReport& a, const RdeReport& b);

/// sRGB transfer (IEC 61966-2-1), 8-bit code to linear [0,1]; a 256-entry table.
MRGI_API float srgb8_to_linear(uint8_t v);

}  // namespace mrgi
