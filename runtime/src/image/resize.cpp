// Resampling of camera frames, references and masks to another output size (replay, bench).
#include <algorithm>
#include <cmath>

#include "mrgi/image.h"

namespace mrgi {

ImageRGB8 resize_bilinear(const ImageRGB8& src, int w, int h) {
  if (src.width == w && src.height == h) return src;
  ImageRGB8 out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double sx = std::clamp((x + 0.5) * src.width / w - 0.5, 0.0, src.width - 1.0);
      const double sy = std::clamp((y + 0.5) * src.height / h - 0.5, 0.0, src.height - 1.0);
      const int x0 = int(sx), y0 = int(sy);
      const int x1 = std::min(x0 + 1, src.width - 1), y1 = std::min(y0 + 1, src.height - 1);
      const double fx = sx - x0, fy = sy - y0;
      for (int c = 0; c < 3; ++c) {
        const double v = (1 - fy) * ((1 - fx) * src.at(x0, y0)[c] + fx * src.at(x1, y0)[c]) +
                         fy * ((1 - fx) * src.at(x0, y1)[c] + fx * src.at(x1, y1)[c]);
        out.at(x, y)[c] = uint8_t(std::lround(v));
      }
    }
  return out;
}

ImageU8 resize_nearest(const ImageU8& src, int w, int h) {
  if (src.width == w && src.height == h) return src;
  ImageU8 out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      out.at(x, y)[0] = *src.at(std::min(src.width - 1, x * src.width / w), std::min(src.height - 1, y * src.height / h));
  return out;
}

}  // namespace mrgi
