#include "image/srgb.h"

#include <algorithm>
#include <cmath>

namespace mrgi {

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float l) {
  if (!(l > 0.0f)) return 0.0f;  // also maps NaN to 0
  if (l >= 1.0f) return 1.0f;
  return l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
}

const std::array<float, 256>& srgb8_to_linear_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_to_linear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

uint8_t linear_to_srgb8(float linear) {
  return uint8_t(std::lround(linear_to_srgb(linear) * 255.0f));
}

}  // namespace mrgi
