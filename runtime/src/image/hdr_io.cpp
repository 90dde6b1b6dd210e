// HDR environment images: OpenEXR (read with the OpenEXR library, written with tinyexr), Radiance
// .hdr through stb_image, and 8-bit sRGB PNG decoded to linear. All come back as linear RGB float.
//
// The one stb_image implementation in the program. It must be the full decoder: its symbols
// also satisfy libtinygltf.so's references (ELF interposition) for its default image loader,
// which mrgi no longer uses: glTF textures go through libpng / libjpeg-turbo
// (image/texture_decode.h, set by the glTF loader), since a mutated JPEG made stb 2.27 write out
// of bounds. stb decodes Radiance .hdr only here, after its header's size is checked.
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <tinyexr.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImathBox.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "image/file_io.h"
#include "image/srgb.h"
#include "mrgi/image.h"

namespace mrgi {
namespace {

// Environment images up to 16384 x 8192 (a 16k equirectangular map, 1.5 GiB as RGB float), and
// no side over 16384: a 5-million-pixel-wide strip is no environment (fuzz_hdr's 10-minute run
// found an OpenEXR header asking for one; reading it took the fuzzer's whole time budget).
constexpr uint64_t kMaxHdrPixels = 16384ull * 8192ull;
constexpr int kMaxHdrSide = 16384;

Status check_hdr_size(int w, int h, const std::string& path, const char* format) {
  if (w <= 0 || h <= 0 || w > kMaxHdrSide || h > kMaxHdrSide || uint64_t(w) * uint64_t(h) > kMaxHdrPixels)
    return fail(ErrorKind::BadInput, path + ": " + format + " image is " + std::to_string(w) + "x" +
                                         std::to_string(h) + ", over the limit of 16384x8192 pixels (at "
                                         "most 16384 a side), or empty");
  return ok_status();
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Radiance is finite; one NaN or Inf would poison every sum (importance sampling, SH) built on it.
Status check_finite(const std::string& path, const ImageRGBF& img) {
  for (size_t i = 0; i < img.data.size(); ++i) {
    if (!std::isfinite(img.data[i])) {
      const size_t pixel = i / 3;
      return fail(ErrorKind::BadInput,
                  path + ": pixel (" + std::to_string(pixel % size_t(img.width)) + ", " +
                      std::to_string(pixel / size_t(img.width)) + ") channel " +
                      std::to_string(i % 3) + " is " + (std::isnan(img.data[i]) ? "NaN" : "infinite") +
                      "; HDR images must hold finite radiance");
    }
  }
  return ok_status();
}

// Reading goes through the OpenEXR library rather than tinyexr: tinyexr cannot decode DWAA/DWAB,
// the compression of the HDRI Haven maps Blender ships (../shared/data/env/*.exr).
Expected<ImageRGBF> load_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const int w = window.max.x - window.min.x + 1, h = window.max.y - window.min.y + 1;
    MRGI_TRY(check_hdr_size(w, h, path, "OpenEXR"));
    const Imf::ChannelList& channels = file.header().channels();
    // RGB, or a single luminance channel Y repeated into all three.
    const bool rgb = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
    const bool grey = !rgb && channels.findChannel("Y");
    if (!rgb && !grey)
      return fail(ErrorKind::BadInput, path + ": OpenEXR image has neither R, G, B nor Y channels");
    ImageRGBF img(w, h);
    const size_t xs = 3 * sizeof(float), ys = xs * size_t(w);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)  // Slice::Make addresses the buffer in data-window coordinates
      fb.insert(grey ? "Y" : names[c],
                Imf::Slice::Make(Imf::FLOAT, img.data.data() + c, window, xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return img;
  } catch (const std::exception& e) {
    return fail(ErrorKind::BadInput, path + ": cannot decode OpenEXR: " + e.what());
  }
}

// stb_image's Radiance decoder (Debian's 2.27+) never returns on a run-length-encoded scanline
// whose data stops early or holds a literal run of length 0: it reads 0 past the end and loops
// without advancing (found by fuzz_hdr: a 69-byte file hung it). This walks the RLE control
// bytes as stbi__hdr_load does and refuses such a file first: a scanline's four channels must
// each be filled by runs of 1 .. what is left, within the data. Scanlines stb reads flat (width
// outside [8, 32768), or the first one without the 2, 2 marker, after which stb reads the rest
// flat) must be all there: 4 bytes a pixel to the image's end.
Status check_hdr_runs(const std::vector<uint8_t>& data, int w, int h, const std::string& path) {
  size_t pos = 0;
  const size_t n = data.size();
  auto get8 = [&]() -> int { return pos < n ? data[pos++] : 0; };  // stb reads 0 past the end
  // Pixel data starts where stb's header reader stops, found the way it reads
  // (stbi__hdr_gettoken): a line is the bytes up to '\n' (at most 1023, the rest skipped), and
  // the header ends at the first line after the signature that is empty or starts with a NUL
  // byte; the resolution line follows. Looking for "\n\n" instead found the wrong start on a
  // header line of NUL bytes, and stb hung on data this walk never saw (fuzz_hdr).
  auto line_first_byte = [&]() -> int {
    int len = 0, first = 0;
    int c = get8();
    while (pos < n && c != '\n') {
      if (len == 0) first = c;
      if (++len == 1023) {
        while (pos < n && get8() != '\n') {
        }
        break;
      }
      c = get8();
    }
    return len == 0 ? 0 : first;
  };
  line_first_byte();  // the signature
  while (line_first_byte() != 0) {
  }
  line_first_byte();  // the resolution
  // Flat pixels (4 bytes each) from `at` to the end: stb reads zeros past the data's end, so an
  // image cut short would load with black rows; it is refused instead.
  auto flat_rest = [&](size_t at, int row) -> Status {
    const size_t need = size_t(4) * size_t(w) * size_t(h - row);
    if (n - std::min(at, n) >= need) return ok_status();
    return fail(ErrorKind::BadInput, path + ": Radiance HDR pixel data ends early: rows " + std::to_string(row) +
                                         ".." + std::to_string(h - 1) + " need " + std::to_string(need) +
                                         " bytes (4 a pixel, flat), the file has " + std::to_string(n - std::min(at, n)) +
                                         " (a truncated file?)");
  };
  if (w < 8 || w >= 32768) return flat_rest(pos, 0);
  for (int j = 0; j < h; ++j) {
    const size_t row_start = pos;
    const int c1 = get8(), c2 = get8(), len_hi = get8();
    if (c1 != 2 || c2 != 2 || (len_hi & 0x80)) return flat_rest(row_start, j);  // stb reads the rest flat
    if (((len_hi << 8) | get8()) != w) return ok_status();          // stb refuses it itself
    for (int k = 0; k < 4; ++k) {
      for (int i = 0; i < w;) {
        if (pos >= n)
          return fail(ErrorKind::BadInput, path + ": Radiance HDR scanline " + std::to_string(j) +
                                               " ends early (run-length data stops at byte " +
                                               std::to_string(n) + ")");
        int count = get8();
        const bool run = count > 128;
        if (run) count -= 128;
        if (count == 0 || count > w - i)
          return fail(ErrorKind::BadInput, path + ": Radiance HDR scanline " + std::to_string(j) +
                                               ": run of length " + std::to_string(count) + " with " +
                                               std::to_string(w - i) + " pixels left (corrupt run-length data)");
        pos += run ? 1 : size_t(count);
        i += count;
      }
    }
  }
  return ok_status();
}

Expected<ImageRGBF> load_radiance_hdr(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return bytes.error();
  int w = 0, h = 0, channels = 0;
  // Only a Radiance file goes to stb: its generic entry points try every format it knows, and
  // a 38-byte file read as a TGA header kept its decoder busy for minutes (fuzz_hdr).
  if (!stbi_is_hdr_from_memory(bytes->data(), int(bytes->size())))
    return fail(ErrorKind::BadInput, path + ": not a Radiance HDR image (the file does not start "
                                            "with the #?RADIANCE or #?RGBE signature)");
  // The header's size is checked before stb allocates it (a 2 KB file can ask for 120 GB).
  if (!stbi_info_from_memory(bytes->data(), int(bytes->size()), &w, &h, &channels))
    return fail(ErrorKind::BadInput, path + ": not a Radiance HDR image (header unreadable)");
  MRGI_TRY(check_hdr_size(w, h, path, "Radiance HDR"));
  MRGI_TRY(check_hdr_runs(*bytes, w, h, path));
  float* pixels = stbi_loadf_from_memory(bytes->data(), int(bytes->size()), &w, &h, &channels, 3);
  if (!pixels) {
    const char* why = stbi_failure_reason();  // may be null (stb built without failure strings)
    return fail(ErrorKind::BadInput, path + ": cannot decode Radiance HDR: " + (why ? why : "undecodable"));
  }
  std::unique_ptr<float, decltype(&stbi_image_free)> owner(pixels, &stbi_image_free);
  ImageRGBF img(w, h);
  std::copy(pixels, pixels + img.data.size(), img.data.begin());
  return img;
}

Expected<ImageRGBF> load_srgb_png(const std::string& path) {
  auto png = load_png_rgb8(path);
  if (!png) return png.error();
  const auto& table = srgb8_to_linear_table();
  ImageRGBF img(png->width, png->height);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = table[png->data[i]];
  return img;
}

}  // namespace

Expected<ImageRGBF> load_hdr_image(const std::string& path) {
  const std::string ext = lower_extension(path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(ErrorKind::NotFound, path + ": file does not exist (or is not a regular file)");
  Expected<ImageRGBF> img = ImageRGBF{};
  if (ext == ".exr") img = load_exr(path);
  else if (ext == ".hdr") img = load_radiance_hdr(path);
  else if (ext == ".png") img = load_srgb_png(path);
  else
    return fail(ErrorKind::BadInput, path + ": unsupported HDR image extension '" + ext +
                                         "'; expected .exr, .hdr or .png");
  if (!img) return img.error();
  MRGI_TRY(check_finite(path, *img));
  // Lossy EXR codecs (DWAA/DWAB) ring slightly below zero near sharp highlights (the shared
  // HDRI maps hold values down to -0.003); radiance cannot be negative, and negative weights
  // would break importance sampling and SH projection downstream.
  for (float& v : img->data) v = std::max(v, 0.0f);
  return img;
}

// 32-bit float channels (not half) so a written image reads back bit-identical.
Status write_exr(const std::string& path, const ImageRGBF& img) {
  if (img.empty() || img.data.size() != img.pixel_count() * 3)
    return fail(ErrorKind::BadUsage, path + ": cannot write OpenEXR: image is empty or its data "
                                            "size is not width*height*3");
  MRGI_TRY(check_finite(path, img));
  const std::string tmp = path + ".tmp";
  const char* err = nullptr;
  const int rc = SaveEXR(img.data.data(), img.width, img.height, 3, /*save_as_fp16=*/0, tmp.c_str(), &err);
  if (rc != TINYEXR_SUCCESS) {
    std::string why = err ? err : ("tinyexr error " + std::to_string(rc));
    if (err) FreeEXRErrorMessage(err);
    std::remove(tmp.c_str());
    return fail(ErrorKind::Device, path + ": cannot write OpenEXR: " + why);
  }
  return rename_into_place(tmp, path);
}

}  // namespace mrgi
