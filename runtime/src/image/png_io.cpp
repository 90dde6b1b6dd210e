// PNG I/O through libpng's classic API. stb_image cannot write 16-bit PNG and hides a file's
// real bit depth, which the capture rules (8-bit colour, 16-bit depth) must check and report.
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "image/file_io.h"
#include "image/texture_decode.h"
#include "mrgi/image.h"

namespace mrgi {
namespace {

// What a PNG holds, after only lossless unpacking: palette -> RGB(A) (tRNS -> alpha), grey below
// 8 bits -> 8 bits, 16-bit samples in host byte order.
struct DecodedPng {
  int width = 0, height = 0;
  int channels = 0;              // after palette expansion
  int bit_depth = 0;             // 8 or 16 after unpacking
  int file_bit_depth = 0;        // as stored in the file
  int file_color_type = 0;       // PNG_COLOR_TYPE_*
  std::vector<uint8_t> bytes;    // width * height * channels * bit_depth / 8
};

struct MemoryReader {
  const uint8_t* data;
  size_t size, pos;
};

struct PngErrorSink {
  std::jmp_buf jump;
  char message[256];
};

void on_png_error(png_structp png, png_const_charp msg) {
  auto* sink = static_cast<PngErrorSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof(sink->message), "%s", msg);
  std::longjmp(sink->jump, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

void read_from_memory(png_structp png, png_bytep out, png_size_t count) {
  auto* src = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (src->pos + count > src->size) png_error(png, "file is truncated");
  std::memcpy(out, src->data + src->pos, count);
  src->pos += count;
}

// Only plain C data lives in this frame across setjmp; `out` is owned by the caller.
// Returns false with sink->message set on a libpng error.
bool decode_png_bytes(const std::vector<uint8_t>& file, DecodedPng* out, PngErrorSink* sink) {
  if (file.size() < 8 || png_sig_cmp(file.data(), 0, 8) != 0) {
    std::snprintf(sink->message, sizeof(sink->message), "not a PNG file (bad signature)");
    return false;
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, sink, on_png_error, on_png_warning);
  if (!png) {
    std::snprintf(sink->message, sizeof(sink->message), "libpng could not start");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  MemoryReader reader{file.data(), file.size(), 0};
  std::vector<png_bytep>* rows = new std::vector<png_bytep>();
  if (setjmp(sink->jump)) {
    delete rows;
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  if (!info) png_error(png, "libpng could not allocate its info struct");
  png_set_read_fn(png, &reader, read_from_memory);
  // Bound the size a corrupt header can make us allocate (16k x 16k).
  png_set_user_limits(png, 16384, 16384);
  png_read_info(png, info);
  out->width = int(png_get_image_width(png, info));
  out->height = int(png_get_image_height(png, info));
  out->file_bit_depth = png_get_bit_depth(png, info);
  out->file_color_type = png_get_color_type(png, info);
  if (out->file_color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (out->file_color_type == PNG_COLOR_TYPE_GRAY && out->file_bit_depth < 8)
    png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (out->file_bit_depth == 16) {
    const uint16_t probe = 1;
    uint8_t first_byte;
    std::memcpy(&first_byte, &probe, 1);
    if (first_byte == 1) png_set_swap(png);  // PNG is big-endian; the host is little-endian
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  out->channels = png_get_channels(png, info);
  out->bit_depth = png_get_bit_depth(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  out->bytes.resize(row_bytes * size_t(out->height));
  rows->resize(size_t(out->height));
  for (int y = 0; y < out->height; ++y) (*rows)[size_t(y)] = out->bytes.data() + row_bytes * size_t(y);
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  delete rows;
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

std::string describe_file_format(const DecodedPng& d) {
  const char* type = "unknown colour type";
  switch (d.file_color_type) {
    case PNG_COLOR_TYPE_GRAY: type = "grey"; break;
    case PNG_COLOR_TYPE_GRAY_ALPHA: type = "grey+alpha"; break;
    case PNG_COLOR_TYPE_RGB: type = "RGB"; break;
    case PNG_COLOR_TYPE_RGB_ALPHA: type = "RGBA"; break;
    case PNG_COLOR_TYPE_PALETTE: type = "palette"; break;
  }
  const bool transparency = (d.file_color_type == PNG_COLOR_TYPE_RGB && d.channels == 4) ||
                            (d.file_color_type == PNG_COLOR_TYPE_GRAY && d.channels == 2);
  return std::to_string(d.file_bit_depth) + "-bit " + type +
         (transparency ? " with tRNS transparency" : "") + " (" + std::to_string(d.width) + "x" +
         std::to_string(d.height) + ")";
}

Expected<DecodedPng> decode_png_file(const std::string& path) {
  auto file = read_file_bytes(path);
  if (!file) return file.error();
  DecodedPng decoded;
  PngErrorSink sink{};
  if (!decode_png_bytes(*file, &decoded, &sink))
    return fail(ErrorKind::BadInput, path + ": cannot decode PNG: " + sink.message);
  return decoded;
}

Error wrong_format(const std::string& path, const DecodedPng& d, const char* expected) {
  return fail(ErrorKind::BadInput,
              path + ": PNG is " + describe_file_format(d) + ", expected " + expected);
}

template <class T, int C>
Image<T, C> copy_pixels(const DecodedPng& d) {
  Image<T, C> img(d.width, d.height);
  std::memcpy(img.data.data(), d.bytes.data(), img.data.size() * sizeof(T));
  return img;
}

struct PngLayout {
  int color_type;
  int bit_depth;
  PngEffort effort = PngEffort::Fast;
};

bool encode_png_file(const std::string& path, int width, int height, PngLayout layout,
                     const uint8_t* pixels, size_t row_bytes, PngErrorSink* sink) {
  FILE* fp = std::fopen(path.c_str(), "wb");
  if (!fp) {
    std::snprintf(sink->message, sizeof(sink->message), "cannot open for writing: %s",
                  std::strerror(errno));
    return false;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    std::snprintf(sink->message, sizeof(sink->message), "libpng could not start");
    if (png) png_destroy_write_struct(&png, nullptr);
    std::fclose(fp);
    return false;
  }
  if (setjmp(sink->jump)) {
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
    return false;
  }
  png_init_io(png, fp);
  // Level 3 keeps capture writing fast (files ~10% larger than at the default 6); level 9 is for
  // stored data (see PngEffort).
  png_set_compression_level(png, layout.effort == PngEffort::Small ? 9 : 3);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), layout.bit_depth,
               layout.color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (layout.bit_depth == 16) {
    const uint16_t probe = 1;
    uint8_t first_byte;
    std::memcpy(&first_byte, &probe, 1);
    if (first_byte == 1) png_set_swap(png);
  }
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(pixels + row_bytes * size_t(y)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(fp) != 0) {
    std::snprintf(sink->message, sizeof(sink->message), "write failed: %s", std::strerror(errno));
    return false;
  }
  return true;
}

template <class T, int C>
Status write_png_image(const std::string& path, const Image<T, C>& img, PngLayout layout) {
  if (img.empty() || img.data.size() != img.pixel_count() * C)
    return fail(ErrorKind::BadUsage, path + ": cannot write PNG: image is empty or its data size (" +
                                         std::to_string(img.data.size()) + ") is not width*height*" +
                                         std::to_string(C));
  const std::string tmp = path + ".tmp";
  PngErrorSink sink{};
  if (!encode_png_file(tmp, img.width, img.height, layout,
                       reinterpret_cast<const uint8_t*>(img.data.data()),
                       size_t(img.width) * C * sizeof(T), &sink)) {
    std::remove(tmp.c_str());
    return fail(ErrorKind::Device, path + ": cannot write PNG: " + sink.message);
  }
  return rename_into_place(tmp, path);
}

}  // namespace

// Colour: 8-bit RGB. A palette image is an 8-bit RGB image stored indexed, so it is expanded;
// one with transparency, grey, RGBA or 16-bit files are refused (the capture rule).
Expected<ImageRGB8> load_png_rgb8(const std::string& path) {
  auto d = decode_png_file(path);
  if (!d) return d.error();
  if (d->bit_depth != 8 || d->channels != 3)
    return wrong_format(path, *d, "8-bit RGB (colour images are 8-bit sRGB)");
  return copy_pixels<uint8_t, 3>(*d);
}

// RGBA: 8-bit RGBA, or 8-bit RGB / palette given an opaque alpha of 255.
Expected<ImageRGBA8> load_png_rgba8(const std::string& path) {
  auto d = decode_png_file(path);
  if (!d) return d.error();
  if (d->bit_depth == 8 && d->channels == 4) return copy_pixels<uint8_t, 4>(*d);
  if (d->bit_depth == 8 && d->channels == 3) {
    ImageRGBA8 img(d->width, d->height, 255);
    for (size_t i = 0; i < img.pixel_count(); ++i)
      std::memcpy(&img.data[i * 4], &d->bytes[i * 3], 3);
    return img;
  }
  return wrong_format(path, *d, "8-bit RGBA or RGB");
}

// Depth: exactly 16-bit single channel; an 8-bit depth image has lost its metric scale.
Expected<ImageU16> load_png_u16(const std::string& path) {
  auto d = decode_png_file(path);
  if (!d) return d.error();
  if (d->file_color_type != PNG_COLOR_TYPE_GRAY || d->bit_depth != 16 || d->channels != 1)
    return wrong_format(path, *d, "16-bit grey (depth images are 16-bit single-channel)");
  return copy_pixels<uint16_t, 1>(*d);
}

// Masks: 8-bit grey; 1/2/4-bit grey is widened to 8 bits (so 1-bit 1 reads as 255).
Expected<ImageU8> load_png_u8(const std::string& path) {
  auto d = decode_png_file(path);
  if (!d) return d.error();
  if (d->file_color_type != PNG_COLOR_TYPE_GRAY || d->bit_depth != 8 || d->channels != 1)
    return wrong_format(path, *d, "8-bit grey (masks are 8-bit single-channel)");
  return copy_pixels<uint8_t, 1>(*d);
}

Status write_png(const std::string& path, const ImageRGB8& img, PngEffort effort) {
  return write_png_image(path, img, {PNG_COLOR_TYPE_RGB, 8, effort});
}
Status write_png(const std::string& path, const ImageRGBA8& img, PngEffort effort) {
  return write_png_image(path, img, {PNG_COLOR_TYPE_RGB_ALPHA, 8, effort});
}
Status write_png(const std::string& path, const ImageU16& img, PngEffort effort) {
  return write_png_image(path, img, {PNG_COLOR_TYPE_GRAY, 16, effort});
}
Status write_png(const std::string& path, const ImageU8& img, PngEffort effort) {
  return write_png_image(path, img, {PNG_COLOR_TYPE_GRAY, 8, effort});
}

Expected<ImageRGBA8> decode_png_rgba8(const uint8_t* data, size_t size) {
  DecodedPng d;
  PngErrorSink sink{};
  const std::vector<uint8_t> file(data, data + size);
  if (!decode_png_bytes(file, &d, &sink)) return fail(ErrorKind::BadInput, std::string("cannot decode PNG: ") + sink.message);
  if (uint64_t(d.width) * uint64_t(d.height) > kMaxTexturePixels)
    return fail(ErrorKind::BadInput, "PNG is " + std::to_string(d.width) + "x" + std::to_string(d.height) +
                                         ", over the limit of " + std::to_string(kMaxTexturePixels) + " pixels");
  ImageRGBA8 out(d.width, d.height, 255);
  const int bytes_per_sample = d.bit_depth / 8;
  const int ch = d.channels;
  for (size_t i = 0; i < out.pixel_count(); ++i) {
    // The high byte of a 16-bit sample is its 8-bit value (host order: little-endian high last).
    auto sample = [&](int c) -> uint8_t {
      const size_t at = (i * size_t(ch) + size_t(c)) * size_t(bytes_per_sample);
      return bytes_per_sample == 2 ? d.bytes[at + 1] : d.bytes[at];
    };
    uint8_t* px = &out.data[i * 4];
    if (ch >= 3) {
      px[0] = sample(0);
      px[1] = sample(1);
      px[2] = sample(2);
      if (ch == 4) px[3] = sample(3);
    } else {
      px[0] = px[1] = px[2] = sample(0);
      if (ch == 2) px[3] = sample(1);
    }
  }
  return out;
}

}  // namespace mrgi
