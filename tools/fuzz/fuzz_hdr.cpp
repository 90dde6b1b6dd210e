// Fuzz target: environment images (load_hdr_image): Radiance .hdr (stb_image's HDR path only)
// and OpenEXR, picked by the input's magic.
#include <cmath>

#include "fuzz_input.h"
#include "mrgi/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool exr = mrgi::fuzz::starts_with(data, size, "\x76\x2f\x31\x01");
  const std::string path = mrgi::fuzz::InputFolder::get().write(exr ? "env.exr" : "env.hdr", data, size);
  auto img = mrgi::load_hdr_image(path);
  if (img.ok()) {
    if (img->data.size() != size_t(img->width) * size_t(img->height) * 3u) std::abort();
    for (float v : img->data)
      if (!std::isfinite(v)) std::abort();  // the loader promises finite radiance
  }
  return 0;
}
