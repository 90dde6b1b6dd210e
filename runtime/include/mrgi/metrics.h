// Error metrics shared by the runtime, the tests and the bench (DESIGN.md "Ground truth and
// error"). All differences are taken in linear RGB after decoding sRGB.
#pragma once
#include "mrgi/expected.h"
#include "mrgi/image.h"

namespace mrgi {

// Which pixels a figure covers. Virtual pixels are those where the reference differs from the
// camera frame because a virtual object is seen there; the mask comes from the caller (the
// synthetic capture knows it; the runtime knows its own virtual mask).
struct ErrorFigures {
  double rde = 0.0;        // ||(O-C)-(G-C)|| / ||G-C||; 0 perfect, 1 = camera frame untouched
  double rmse8 = 0.0;      // RMSE of O vs G in 8-bit sRGB units
  double ssim = 1.0;       // mean SSIM of luma (8x8 windows... see metrics.cpp)
  size_t pixels = 0;
};

struct RdeReport {
  ErrorFigures all, real, virtual_;
};

// mask: nullptr = every pixel real; else 1 byte per pixel, non-zero = virtual.
// Returns BadInput when sizes differ. When ||G-C|| is 0 over a set, rde is 0 if O==C there too
// and +inf otherwise is avoided: reported as ||O-C|| / (1 linear unit * pixels) instead, flagged.
Expected<RdeReport> measure_error(const ImageRGB8& output, const ImageRGB8& camera,
                                  const ImageRGB8& reference, const Image<uint8_t, 1>* virtual_mask);

}  // namespace mrgi
