#include "mrgi/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace mrgi {
namespace {

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

// Separable 11-tap Gaussian (sigma 1.5), edges clamped: the SSIM window of Wang et al. 2004.
std::vector<double> gaussian_blur(const std::vector<double>& src, int w, int h) {
  static const std::array<double, 11> k = [] {
    std::array<double, 11> g{};
    double sum = 0.0;
    for (int i = 0; i < 11; ++i) sum += g[i] = std::exp(-0.5 * std::pow((i - 5) / 1.5, 2.0));
    for (double& v : g) v /= sum;
    return g;
  }();
  std::vector<double> tmp(src.size()), out(src.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int i = 0; i < 11; ++i) s += k[i] * src[size_t(y) * w + std::clamp(x + i - 5, 0, w - 1)];
      tmp[size_t(y) * w + x] = s;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int i = 0; i < 11; ++i) s += k[i] * tmp[size_t(std::clamp(y + i - 5, 0, h - 1)) * w + x];
      out[size_t(y) * w + x] = s;
    }
  return out;
}

// Per-pixel SSIM map of sRGB luma in 8-bit units (C1 = (0.01*255)^2, C2 = (0.03*255)^2).
template <int CO>
std::vector<double> ssim_map(const Image<uint8_t, CO>& o, const ImageRGB8& g) {
  const int w = g.width, h = g.height;
  const size_t n = g.pixel_count();
  std::vector<double> a(n), b(n), aa(n), bb(n), ab(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* po = &o.data[i * CO];
    const uint8_t* pg = &g.data[i * 3];
    a[i] = 0.299 * po[0] + 0.587 * po[1] + 0.114 * po[2];
    b[i] = 0.299 * pg[0] + 0.587 * pg[1] + 0.114 * pg[2];
    aa[i] = a[i] * a[i];
    bb[i] = b[i] * b[i];
    ab[i] = a[i] * b[i];
  }
  const auto ma = gaussian_blur(a, w, h), mb = gaussian_blur(b, w, h);
  const auto saa = gaussian_blur(aa, w, h), sbb = gaussian_blur(bb, w, h), sab = gaussian_blur(ab, w, h);
  const double c1 = std::pow(0.01 * 255.0, 2.0), c2 = std::pow(0.03 * 255.0, 2.0);
  std::vector<double> s(n);
  for (size_t i = 0; i < n; ++i) {
    const double va = saa[i] - ma[i] * ma[i], vb = sbb[i] - mb[i] * mb[i], cov = sab[i] - ma[i] * mb[i];
    s[i] = ((2 * ma[i] * mb[i] + c1) * (2 * cov + c2)) /
           ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
  }
  return s;
}

struct Accumulator {
  double err2 = 0.0, ref2 = 0.0, rmse2 = 0.0, ssim = 0.0, change = 0.0, truth_change = 0.0;
  double change_rgb[3] = {0.0, 0.0, 0.0}, truth_change_rgb[3] = {0.0, 0.0, 0.0};
  size_t pixels = 0;
  ErrorFigures finish() const {
    ErrorFigures f;
    f.pixels = pixels;
    f.err2 = err2;
    f.ref2 = ref2;
    f.change_sum = change;
    f.truth_change_sum = truth_change;
    for (int k = 0; k < 3; ++k) {
      f.change_rgb[k] = change_rgb[k];
      f.truth_change_rgb[k] = truth_change_rgb[k];
    }
    if (pixels == 0) return f;
    // ||G-C|| below one 8-bit step's worth over the set counts as "nothing to change".
    const double floor = 1e-12;
    f.rde_defined = ref2 > floor;
    f.rde = f.rde_defined ? std::sqrt(err2 / ref2) : 0.0;
    f.delta_rms = std::sqrt(err2 / (3.0 * double(pixels)));
    f.rmse8 = std::sqrt(rmse2 / (3.0 * double(pixels)));
    f.ssim = ssim / double(pixels);
    return f;
  }
};

// 1 where a pixel of the other side of the mask lies within kSilhouetteBandPx (Euclidean).
std::vector<uint8_t> silhouette_band(const ImageU8& mask) {
  const int w = mask.width, h = mask.height, r = kSilhouetteBandPx;
  std::vector<uint8_t> band(mask.pixel_count(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool v = mask.data[size_t(y) * w + x] != 0;
      bool edge = false;
      for (int dy = -r; dy <= r && !edge; ++dy)
        for (int dx = -r; dx <= r && !edge; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (dx * dx + dy * dy > r * r || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          edge = (mask.data[size_t(ny) * w + nx] != 0) != v;
        }
      band[size_t(y) * w + x] = edge ? 1 : 0;
    }
  return band;
}

template <int CO>
Expected<RdeReport> measure(const Image<uint8_t, CO>& o, const ImageRGB8& c, const ImageRGB8& g,
                            const ImageU8* mask) {
  auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
  if (o.width != g.width || o.height != g.height || c.width != g.width || c.height != g.height)
    return fail(ErrorKind::BadInput, "measure_error: image sizes differ (output " + size(o.width, o.height) +
                                         ", camera " + size(c.width, c.height) + ", reference " +
                                         size(g.width, g.height) + "); all three must match");
  if (mask && (mask->width != g.width || mask->height != g.height))
    return fail(ErrorKind::BadInput, "measure_error: virtual mask is " + size(mask->width, mask->height) +
                                         ", reference is " + size(g.width, g.height));
  const auto& lin = srgb_table();
  const auto ssim = ssim_map(o, g);
  const std::vector<uint8_t> band = mask ? silhouette_band(*mask) : std::vector<uint8_t>{};
  Accumulator all, real, virt, influenced, rest, darkened, brightened, silhouette;
  const double luma[3] = {0.2126, 0.7152, 0.0722};  // Rec. 709, linear
  for (size_t i = 0; i < g.pixel_count(); ++i) {
    double e2 = 0.0, r2 = 0.0, m2 = 0.0, change = 0.0, truth_change = 0.0, truth_luma = 0.0;
    double change_rgb[3], truth_rgb[3];
    bool changed = false;
    for (int k = 0; k < 3; ++k) {
      const uint8_t c8 = c.data[i * 3 + k];
      const double ov = lin[o.data[i * CO + k]], cv = lin[c8], gv = lin[g.data[i * 3 + k]];
      e2 += (ov - gv) * (ov - gv);  // (O-C)-(G-C) = O-G
      r2 += (gv - cv) * (gv - cv);
      change += ov - cv;
      truth_change += gv - cv;
      change_rgb[k] = ov - cv;
      truth_rgb[k] = gv - cv;
      truth_luma += luma[k] * (gv - cv);
      const double d8 = double(o.data[i * CO + k]) - double(g.data[i * 3 + k]);
      m2 += d8 * d8;
      // One sRGB code step at C's level, linear (the larger of the steps on either side).
      const double step = std::max(lin[std::min(255, c8 + 1)] - lin[c8], lin[c8] - lin[std::max(0, c8 - 1)]);
      changed = changed || std::abs(gv - cv) > 3.0 * step;
    }
    const bool is_virtual = mask && mask->data[i];
    Accumulator* split = is_virtual ? nullptr : (changed ? &influenced : &rest);
    Accumulator* effect = is_virtual || !changed ? nullptr : (truth_luma < 0.0 ? &darkened : &brightened);
    Accumulator* edge = mask && band[i] ? &silhouette : nullptr;
    for (Accumulator* acc : {&all, is_virtual ? &virt : &real, split, effect, edge}) {
      if (!acc) continue;
      acc->err2 += e2;
      acc->ref2 += r2;
      acc->rmse2 += m2;
      acc->ssim += ssim[i];
      acc->change += change;
      acc->truth_change += truth_change;
      for (int k = 0; k < 3; ++k) {
        acc->change_rgb[k] += change_rgb[k];
        acc->truth_change_rgb[k] += truth_rgb[k];
      }
      acc->pixels += 1;
    }
  }
  return RdeReport{all.finish(),  real.finish(),     virt.finish(),       influenced.finish(),
                   rest.finish(), darkened.finish(), brightened.finish(), silhouette.finish()};
}

}  // namespace

float srgb8_to_linear(uint8_t v) { return srgb_table()[v]; }

ErrorFigures pool(const ErrorFigures& a, const ErrorFigures& b) {
  Accumulator acc;
  acc.pixels = a.pixels + b.pixels;
  acc.err2 = a.err2 + b.err2;
  acc.ref2 = a.ref2 + b.ref2;
  acc.rmse2 = (a.rmse8 * a.rmse8 * double(a.pixels) + b.rmse8 * b.rmse8 * double(b.pixels)) * 3.0;
  acc.ssim = a.ssim * double(a.pixels) + b.ssim * double(b.pixels);
  acc.change = a.change_sum + b.change_sum;
  acc.truth_change = a.truth_change_sum + b.truth_change_sum;
  for (int k = 0; k < 3; ++k) {
    acc.change_rgb[k] = a.change_rgb[k] + b.change_rgb[k];
    acc.truth_change_rgb[k] = a.truth_change_rgb[k] + b.truth_change_rgb[k];
  }
  return acc.finish();
}

RdeReport pool(const RdeReport& a, const RdeReport& b) {
  return {pool(a.all, b.all),           pool(a.real, b.real),         pool(a.virtual_, b.virtual_),
          pool(a.influenced, b.influenced), pool(a.rest, b.rest),         pool(a.darkened, b.darkened),
          pool(a.brightened, b.brightened), pool(a.silhouette, b.silhouette)};
}

Expected<RdeReport> measure_error(const ImageRGB8& output, const ImageRGB8& camera,
                                  const ImageRGB8& reference, const ImageU8* virtual_mask) {
  return measure(output, camera, reference, virtual_mask);
}

Expected<RdeReport> measure_error(const ImageRGBA8& output, const ImageRGB8& camera,
                                  const ImageRGB8& reference, const ImageU8* virtual_mask) {
  return measure(output, camera, reference, virtual_mask);
}

}  // namespace mrgi
