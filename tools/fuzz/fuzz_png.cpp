// Fuzz target: the capture's PNG readers (colour RGB8 and depth u16, libpng), from a file.
#include "fuzz_input.h"
#include "mrgi/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mrgi::fuzz::InputFolder::get().write("frame.png", data, size);
  auto rgb = mrgi::load_png_rgb8(path);
  if (rgb.ok() && rgb->data.size() != size_t(rgb->width) * size_t(rgb->height) * 3u) std::abort();
  auto depth = mrgi::load_png_u16(path);
  if (depth.ok() && depth->data.size() != size_t(depth->width) * size_t(depth->height)) std::abort();
  return 0;
}
