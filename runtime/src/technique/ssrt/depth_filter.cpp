#include "technique/ssrt/depth_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace mrgi::ssrt {
namespace {

bool valid_depth(float d) { return d > 0.0f && std::isfinite(d); }

// Lower median of the first n values (modifies the buffer).
float lower_median(float* v, int n) {
  const int mid = (n - 1) / 2;
  std::nth_element(v, v + mid, v + n);
  return v[mid];
}

struct Window {
  int radius = 0;
  int stride = 1;
};

Window make_window(uint32_t k, uint32_t taps) {
  const uint32_t side = window_side(k);
  return Window{int(side / 2), int(window_stride(side, taps))};
}

}  // namespace

uint32_t window_side(uint32_t k) { return std::max(1u, k | 1u); }

uint32_t window_stride(uint32_t side, uint32_t taps) {
  if (taps <= 1 || side <= taps) return 1;
  return std::max(1u, (side - 1) / (taps - 1));
}

Status validate(const DepthFilterSettings& s) {
  auto bad = [](const char* field, const char* rule) {
    return fail(ErrorKind::BadUsage, std::string("ssrt DepthFilterSettings.") + field + ": " + rule);
  };
  if (s.merge_window < 1 || s.merge_window > 64) return bad("merge_window", "must be 1..64 pixels");
  if (s.bilateral_window < 1 || s.bilateral_window > 64)
    return bad("bilateral_window", "must be 1..64 pixels");
  if (s.final_window < 1 || s.final_window > 8) return bad("final_window", "must be 1..8 pixels");
  if (!(s.intensity_threshold > 0.0f) || !std::isfinite(s.intensity_threshold))
    return bad("intensity_threshold", "must be finite and > 0 grey levels");
  if (!(s.depth_threshold_m > 0.0f) || !std::isfinite(s.depth_threshold_m))
    return bad("depth_threshold_m", "must be finite and > 0 metres");
  if (s.median_taps < 1 || s.median_taps > 9) return bad("median_taps", "must be 1..9");
  return ok_status();
}

Expected<DepthFilterOutput> filter_depth_reference(const DepthFilterInput& in,
                                                   const DepthFilterSettings& s) {
  MRGI_TRY(validate(s));
  if (in.width == 0 || in.height == 0 || !in.depth_camera || !in.intensity) {
    return fail(ErrorKind::BadInput,
                "ssrt depth filter: input needs width, height, depth_camera and intensity");
  }
  const int w = int(in.width), h = int(in.height);
  const size_t count = size_t(w) * h;
  const float* dc = in.depth_camera;
  const float* ic = in.intensity;
  auto dv = [&](int i) { return in.depth_volume ? in.depth_volume[i] : 0.0f; };
  DepthFilterOutput out;
  out.merged.assign(count, 0.0f);
  out.bilateral.assign(count, 0.0f);
  out.final.assign(count, 0.0f);
  std::array<float, 81> buf{};  // 9 x 9 taps at most (median_taps <= 9)
  std::vector<float> big;       // D''' windows (up to 17 x 17)
  big.reserve(17 * 17);

  // D' (eq. 1-3).
  const Window wm = make_window(s.merge_window, s.median_taps);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      const float d_c = dc[p], d_v = dv(p);
      if (valid_depth(d_c)) {
        const bool agree = valid_depth(d_v) && std::abs(d_c - d_v) < s.depth_threshold_m;
        out.merged[p] = agree ? d_v : d_c;
        continue;
      }
      int n_i = 0, n_d = 0;
      for (int dy = -wm.radius; dy <= wm.radius; dy += wm.stride) {
        for (int dx = -wm.radius; dx <= wm.radius; dx += wm.stride) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const int q = qy * w + qx;
          if (!valid_depth(dc[q])) continue;                                   // Omega_k
          if (!(std::abs(ic[p] - ic[q]) < s.intensity_threshold)) continue;   // Omega_I, eq. 1
          buf[n_i++] = dc[q];
          if (valid_depth(dv(q)) && std::abs(dc[q] - dv(q)) < s.depth_threshold_m) ++n_d;  // eq. 2
        }
      }
      if (valid_depth(d_v) && 2 * n_d >= n_i) {
        out.merged[p] = d_v;
      } else if (n_i > 0) {
        out.merged[p] = lower_median(buf.data(), n_i);
      } else {
        out.merged[p] = 0.0f;  // no support and no volume: stays missing
      }
    }
  }

  // D'' (eq. 4): joint bilateral median over Omega_I, sub-sampled.
  const Window wb = make_window(s.bilateral_window, s.median_taps);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      int n = 0;
      for (int dy = -wb.radius; dy <= wb.radius; dy += wb.stride) {
        for (int dx = -wb.radius; dx <= wb.radius; dx += wb.stride) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const int q = qy * w + qx;
          if (!valid_depth(out.merged[q])) continue;
          if (!(std::abs(ic[p] - ic[q]) < s.intensity_threshold)) continue;
          buf[n++] = out.merged[q];
        }
      }
      out.bilateral[p] = n > 0 ? lower_median(buf.data(), n) : out.merged[p];
    }
  }

  // D''' (eq. 5): plain median, every pixel of the small window.
  if (!s.final_pass) {
    out.final = out.bilateral;
    return out;
  }
  const int rf = int(window_side(s.final_window) / 2);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      big.clear();
      for (int dy = -rf; dy <= rf; ++dy) {
        for (int dx = -rf; dx <= rf; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const float d = out.bilateral[qy * w + qx];
          if (valid_depth(d)) big.push_back(d);
        }
      }
      const int p = y * w + x;
      out.final[p] = big.empty() ? 0.0f : lower_median(big.data(), int(big.size()));
    }
  }
  return out;
}

}  // namespace mrgi::ssrt
