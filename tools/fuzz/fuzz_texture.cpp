// Fuzz target: glTF texture decoding from memory (image/texture_decode.h): PNG by libpng, JPEG by
// libjpeg-turbo, picked by the input's magic as the glTF loader picks them.
#include "fuzz_input.h"
#include "image/texture_decode.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto img = mrgi::fuzz::starts_with(data, size, "\x89PNG") ? mrgi::decode_png_rgba8(data, size)
                                                             : mrgi::decode_jpeg_rgba8(data, size);
  if (img.ok() && img->data.size() != size_t(img->width) * size_t(img->height) * 4u) std::abort();
  return 0;
}
