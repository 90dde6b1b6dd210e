// Texture decoding from memory for the glTF loader (and anything else that gets PNG or JPEG
// bytes): libpng and libjpeg-turbo, maintained decoders that survive mutated input, instead of
// stb_image (a mutated JPEG texture made stb 2.27 write past its Huffman tables under ASan).
// Both refuse images over kMaxTexturePixels before allocating them.
#pragma once
#include <cstddef>
#include <cstdint>

#include "mrgi/expected.h"
#include "mrgi/image.h"

namespace mrgi {

constexpr uint64_t kMaxTexturePixels = 8192ull * 8192ull;  // 256 MiB as RGBA8

// Any 8- or 16-bit PNG (grey, grey+alpha, RGB, RGBA, palette) as 8-bit RGBA.
Expected<ImageRGBA8> decode_png_rgba8(const uint8_t* data, size_t size);
// Baseline or progressive JPEG (grey, YCbCr, CMYK refused) as 8-bit RGBA.
Expected<ImageRGBA8> decode_jpeg_rgba8(const uint8_t* data, size_t size);

}  // namespace mrgi
