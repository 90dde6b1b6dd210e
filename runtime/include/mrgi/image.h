/// \file
/// CPU images shared by capture I/O, sensors, the reference renderer and metrics.
/// Row-major, tightly packed, top row first, interleaved channels.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/export.h"

namespace mrgi {

template <class T, int C>
struct Image {
  int width = 0;
  int height = 0;
  std::vector<T> data;  ///< width * height * C
  static constexpr int channels = C;

  Image() = default;
  Image(int w, int h, T fill = T{}) : width(w), height(h), data(size_t(w) * h * C, fill) {}
  bool empty() const { return width == 0 || height == 0; }
  size_t pixel_count() const { return size_t(width) * height; }
  T* at(int x, int y) { return &data[(size_t(y) * width + x) * C]; }
  const T* at(int x, int y) const { return &data[(size_t(y) * width + x) * C]; }
};

using ImageRGB8 = Image<uint8_t, 3>;    ///< sRGB-encoded camera colour
using ImageRGBA8 = Image<uint8_t, 4>;   ///< composited output
using ImageU16 = Image<uint16_t, 1>;    ///< depth, depth_scale units per metre, 0 = no measurement
using ImageRGBF = Image<float, 3>;      ///< linear radiance (HDR)
using ImageU8 = Image<uint8_t, 1>;      ///< masks

/// PNG I/O (libpng via stb). Loaders check bit depth and channel count and name the file on error.
MRGI_API Expected<ImageRGB8> load_png_rgb8(const std::string& path);
MRGI_API Expected<ImageRGBA8> load_png_rgba8(const std::string& path);
MRGI_API Expected<ImageU16> load_png_u16(const std::string& path);
MRGI_API Expected<ImageU8> load_png_u8(const std::string& path);
/// Writers write to PATH.tmp then rename, so a failure never leaves a half-written file.
/// Fast (zlib level 3) keeps live recording and replay output cheap; Small (level 9, about 4x the
/// encode time) is for data that is stored and shipped: synthetic captures and converted
/// references come out 3-12 % smaller. The pixels are the same either way.
enum class PngEffort { Fast, Small };
MRGI_API Status write_png(const std::string& path, const ImageRGB8& img, PngEffort effort = PngEffort::Fast);
MRGI_API Status write_png(const std::string& path, const ImageRGBA8& img, PngEffort effort = PngEffort::Fast);
MRGI_API Status write_png(const std::string& path, const ImageU16& img, PngEffort effort = PngEffort::Fast);
MRGI_API Status write_png(const std::string& path, const ImageU8& img, PngEffort effort = PngEffort::Fast);

/// Resampling to w x h, for outputs of another size than the camera: colour bilinear on the
/// encoded values (as a display would scale it), masks nearest. The same size returns a copy.
MRGI_API ImageRGB8 resize_bilinear(const ImageRGB8& src, int w, int h);
MRGI_API ImageU8 resize_nearest(const ImageU8& src, int w, int h);

/// HDR images: .exr (read with OpenEXR: every compression, including DWAA/DWAB; written with
/// tinyexr as 32-bit float), .hdr (stb), .png (8-bit sRGB decoded to linear). NaN or Inf is
/// refused (BadInput naming file and pixel); negative values are clamped to 0 (lossy-codec ringing).
MRGI_API Expected<ImageRGBF> load_hdr_image(const std::string& path);
MRGI_API Status write_exr(const std::string& path, const ImageRGBF& img);

}  // namespace mrgi
