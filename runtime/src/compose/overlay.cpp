// The composite as a premultiplied overlay for passthrough compositors (mrgi/overlay.h says the
// blend and what it cannot express).
#include "mrgi/overlay.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "image/srgb.h"

namespace mrgi {
namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

template <class A, class B>
Status same_size(const A& a, const B& b, const char* what_a, const char* what_b, const char* function) {
  if (a.width == b.width && a.height == b.height) return ok_status();
  return fail(ErrorKind::BadUsage, std::string(function) + ": " + what_b + " is " + size_text(b.width, b.height) +
                                       ", " + what_a + " " + size_text(a.width, a.height) +
                                       " (they must be the same size)");
}

}  // namespace

Expected<ImageRGBA8> make_overlay(const ImageRGBA8& composite, const ImageU8& virtual_mask, const ImageRGB8& camera) {
  MRGI_TRY(same_size(composite, virtual_mask, "the composite", "the virtual mask", "make_overlay"));
  MRGI_TRY(same_size(composite, camera, "the composite", "the camera frame", "make_overlay"));
  const auto& decode = srgb8_to_linear_table();
  ImageRGBA8 overlay(composite.width, composite.height);
  const size_t n = size_t(composite.width) * size_t(composite.height);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* o8 = &composite.data[4 * i];
    uint8_t* out = &overlay.data[4 * i];
    if (virtual_mask.data[i] != 0) {  // the object covers the passthrough
      out[0] = o8[0], out[1] = o8[1], out[2] = o8[2], out[3] = 255;
      continue;
    }
    const uint8_t* c8 = &camera.data[3 * i];
    if (o8[0] == c8[0] && o8[1] == c8[1] && o8[2] == c8[2]) {  // unchanged: fully transparent
      out[0] = out[1] = out[2] = out[3] = 0;
      continue;
    }
    float o[3], c[3], k = 1.0f;
    for (int ch = 0; ch < 3; ++ch) {
      o[ch] = decode[o8[ch]];
      c[ch] = decode[c8[ch]];
      if (c[ch] > 0.0f) k = std::min(k, o[ch] / c[ch]);  // a black channel cannot be darkened
    }
    k = std::clamp(k, 0.0f, 1.0f);
    // The alpha rounded up, so the passthrough's share k' = 1 - a is at most k and o - k' c
    // stays >= 0 in every channel: the rounding lands in the additive part, which carries it.
    const int a = std::clamp(int(std::ceil((1.0f - k) * 255.0f - 1e-4f)), 0, 255);
    const float kept = 1.0f - float(a) / 255.0f;
    for (int ch = 0; ch < 3; ++ch) out[ch] = linear_to_srgb8(std::max(o[ch] - kept * c[ch], 0.0f));
    out[3] = uint8_t(a);
  }
  return overlay;
}

Expected<ImageRGB8> blend_overlay(const ImageRGBA8& overlay, const ImageRGB8& passthrough) {
  MRGI_TRY(same_size(overlay, passthrough, "the overlay", "the passthrough frame", "blend_overlay"));
  const auto& decode = srgb8_to_linear_table();
  ImageRGB8 shown(overlay.width, overlay.height);
  const size_t n = size_t(overlay.width) * size_t(overlay.height);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* s = &overlay.data[4 * i];
    const float kept = 1.0f - float(s[3]) / 255.0f;
    for (int ch = 0; ch < 3; ++ch)
      shown.data[3 * i + size_t(ch)] =
          linear_to_srgb8(decode[s[ch]] + kept * decode[passthrough.data[3 * i + size_t(ch)]]);
  }
  return shown;
}

}  // namespace mrgi
