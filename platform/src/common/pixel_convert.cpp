#include "common/pixel_convert.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cstring>

// Static copy: the runtime compiles its own stb_image for HDR loading; ours stays private.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_JPEG
#include <stb/stb_image.h>

namespace mrgi {
namespace {

uint8_t clamp8(int v) { return uint8_t(std::clamp(v, 0, 255)); }

// BT.601 limited range to RGB in 16.16 fixed point.
inline void yuv_to_rgb(int y, int u, int v, uint8_t* rgb) {
  const int c = (y - 16) * 76309, d = u - 128, e = v - 128;  // 1.164 * 65536
  rgb[0] = clamp8((c + 104597 * e + 32768) >> 16);              // 1.596
  rgb[1] = clamp8((c - 25675 * d - 53279 * e + 32768) >> 16);   // 0.392, 0.813
  rgb[2] = clamp8((c + 132201 * d + 32768) >> 16);              // 2.017
}

inline void rgb_to_yuv(const uint8_t* p, int* y, int* u, int* v) {
  const double r = p[0], g = p[1], b = p[2];
  *y = int(std::clamp(16.0 + 0.2568 * r + 0.5041 * g + 0.0979 * b + 0.5, 16.0, 235.0));
  *u = int(std::clamp(128.0 - 0.1482 * r - 0.2910 * g + 0.4392 * b + 0.5, 16.0, 240.0));
  *v = int(std::clamp(128.0 + 0.4392 * r - 0.3678 * g - 0.0714 * b + 0.5, 16.0, 240.0));
}

std::string describe(const RawFrame& f) {
  return std::string(to_string(f.format)) + " " + std::to_string(f.width) + "x" + std::to_string(f.height) +
         " frame " + std::to_string(f.sequence);
}

// JPEG Annex K.3 tables, as a DHT segment body: {class/id, 16 counts, values} x 4.
const uint8_t kStandardHuffman[] = {
    0x00, 0, 1, 5, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11,
    0x01, 0, 3, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11,
    0x10, 0, 2, 1, 3, 3, 2, 4, 3, 5, 5, 4, 4, 0, 0, 1, 0x7d,
    0x01, 0x02, 0x03, 0x00, 0x04, 0x11, 0x05, 0x12, 0x21, 0x31, 0x41, 0x06, 0x13, 0x51, 0x61, 0x07,
    0x22, 0x71, 0x14, 0x32, 0x81, 0x91, 0xa1, 0x08, 0x23, 0x42, 0xb1, 0xc1, 0x15, 0x52, 0xd1, 0xf0,
    0x24, 0x33, 0x62, 0x72, 0x82, 0x09, 0x0a, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x25, 0x26, 0x27, 0x28,
    0x29, 0x2a, 0x34, 0x35, 0x36, 0x37, 0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48, 0x49,
    0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68, 0x69,
    0x6a, 0x73, 0x74, 0x75, 0x76, 0x77, 0x78, 0x79, 0x7a, 0x83, 0x84, 0x85, 0x86, 0x87, 0x88, 0x89,
    0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98, 0x99, 0x9a, 0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7,
    0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba, 0xc2, 0xc3, 0xc4, 0xc5,
    0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda, 0xe1, 0xe2,
    0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf1, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8,
    0xf9, 0xfa,
    0x11, 0, 2, 1, 2, 4, 4, 3, 4, 7, 5, 4, 4, 0, 1, 2, 0x77,
    0x00, 0x01, 0x02, 0x03, 0x11, 0x04, 0x05, 0x21, 0x31, 0x06, 0x12, 0x41, 0x51, 0x07, 0x61, 0x71,
    0x13, 0x22, 0x32, 0x81, 0x08, 0x14, 0x42, 0x91, 0xa1, 0xb1, 0xc1, 0x09, 0x23, 0x33, 0x52, 0xf0,
    0x15, 0x62, 0x72, 0xd1, 0x0a, 0x16, 0x24, 0x34, 0xe1, 0x25, 0xf1, 0x17, 0x18, 0x19, 0x1a, 0x26,
    0x27, 0x28, 0x29, 0x2a, 0x35, 0x36, 0x37, 0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48,
    0x49, 0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68,
    0x69, 0x6a, 0x73, 0x74, 0x75, 0x76, 0x77, 0x78, 0x79, 0x7a, 0x82, 0x83, 0x84, 0x85, 0x86, 0x87,
    0x88, 0x89, 0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98, 0x99, 0x9a, 0xa2, 0xa3, 0xa4, 0xa5,
    0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba, 0xc2, 0xc3,
    0xc4, 0xc5, 0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda,
    0xe2, 0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8,
    0xf9, 0xfa};

Status decode_mjpeg(const RawFrame& f, ImageRGB8& out) {
  const std::vector<uint8_t> jpeg = mjpeg_with_huffman_tables(f.data, f.size);
  int w = 0, h = 0, n = 0;
  uint8_t* pixels = stbi_load_from_memory(jpeg.data(), int(jpeg.size()), &w, &h, &n, 3);
  if (!pixels) {
    // stb may have no reason to give (null), e.g. when built with STBI_NO_FAILURE_STRINGS.
    const char* why = stbi_failure_reason();
    return fail(ErrorKind::BadInput, describe(f) + ": corrupt JPEG data (" + (why ? why : "undecodable") + ")");
  }
  if (w != f.width || h != f.height) {
    stbi_image_free(pixels);
    return fail(ErrorKind::BadInput, describe(f) + ": the JPEG is " + std::to_string(w) + "x" + std::to_string(h) +
                                         ", the negotiated format says " + std::to_string(f.width) + "x" +
                                         std::to_string(f.height));
  }
  std::memcpy(out.data.data(), pixels, out.data.size());
  stbi_image_free(pixels);
  return ok_status();
}

}  // namespace

const char* to_string(PixelFormat f) {
  switch (f) {
    case PixelFormat::YUYV: return "YUYV";
    case PixelFormat::UYVY: return "UYVY";
    case PixelFormat::RGB24: return "RGB24";
    case PixelFormat::BGR24: return "BGR24";
    case PixelFormat::NV12: return "NV12";
    case PixelFormat::MJPEG: return "MJPEG";
  }
  return "?";
}

std::optional<PixelFormat> pixel_format_from_v4l2(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: return PixelFormat::YUYV;
    case V4L2_PIX_FMT_UYVY: return PixelFormat::UYVY;
    case V4L2_PIX_FMT_RGB24: return PixelFormat::RGB24;
    case V4L2_PIX_FMT_BGR24: return PixelFormat::BGR24;
    case V4L2_PIX_FMT_NV12: return PixelFormat::NV12;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG: return PixelFormat::MJPEG;
    default: return std::nullopt;
  }
}

uint32_t v4l2_fourcc_of(PixelFormat f) {
  switch (f) {
    case PixelFormat::YUYV: return V4L2_PIX_FMT_YUYV;
    case PixelFormat::UYVY: return V4L2_PIX_FMT_UYVY;
    case PixelFormat::RGB24: return V4L2_PIX_FMT_RGB24;
    case PixelFormat::BGR24: return V4L2_PIX_FMT_BGR24;
    case PixelFormat::NV12: return V4L2_PIX_FMT_NV12;
    case PixelFormat::MJPEG: return V4L2_PIX_FMT_MJPEG;
  }
  return 0;
}

std::optional<PixelFormat> pixel_format_from_libcamera(const std::string& name) {
  // libcamera names formats by DRM fourcc: RGB888 is stored B,G,R in memory, BGR888 R,G,B.
  if (name == "YUYV") return PixelFormat::YUYV;
  if (name == "UYVY") return PixelFormat::UYVY;
  if (name == "BGR888") return PixelFormat::RGB24;
  if (name == "RGB888") return PixelFormat::BGR24;
  if (name == "NV12") return PixelFormat::NV12;
  if (name == "MJPEG") return PixelFormat::MJPEG;
  return std::nullopt;
}

std::string fourcc_text(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = char((fourcc >> (8 * i)) & 0xff);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

std::vector<uint8_t> mjpeg_with_huffman_tables(const uint8_t* jpeg, size_t size) {
  std::vector<uint8_t> in(jpeg, jpeg + size);
  if (size < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) return in;  // not a JPEG: let the decoder say so
  size_t at = 2;
  while (at + 4 <= size) {
    if (jpeg[at] != 0xFF) return in;
    const uint8_t marker = jpeg[at + 1];
    if (marker == 0xC4) return in;  // has its own tables
    if (marker == 0xDA) {
      std::vector<uint8_t> out;
      out.reserve(size + sizeof(kStandardHuffman) + 4);
      out.insert(out.end(), jpeg, jpeg + at);
      const size_t len = sizeof(kStandardHuffman) + 2;
      out.push_back(0xFF);
      out.push_back(0xC4);
      out.push_back(uint8_t(len >> 8));
      out.push_back(uint8_t(len & 0xff));
      out.insert(out.end(), kStandardHuffman, kStandardHuffman + sizeof(kStandardHuffman));
      out.insert(out.end(), jpeg + at, jpeg + size);
      return out;
    }
    at += 2 + ((size_t(jpeg[at + 2]) << 8) | jpeg[at + 3]);
  }
  return in;
}

Status convert_to_rgb8(const RawFrame& f, ImageRGB8& out) {
  if (f.width <= 0 || f.height <= 0 || f.width > 16384 || f.height > 16384)
    return fail(ErrorKind::BadInput, describe(f) + ": frame size out of range 1..16384");
  if (!f.data) return fail(ErrorKind::BadInput, describe(f) + ": no data");
  if (out.width != f.width || out.height != f.height) out = ImageRGB8(f.width, f.height);
  const int w = f.width, h = f.height;
  auto need = [&](size_t bytes) -> Status {
    if (f.size < bytes)
      return fail(ErrorKind::BadInput, describe(f) + ": buffer holds " + std::to_string(f.size) + " bytes, needs " +
                                           std::to_string(bytes) + " (short or truncated frame)");
    return ok_status();
  };
  switch (f.format) {
    case PixelFormat::YUYV:
    case PixelFormat::UYVY: {
      if (w % 2) return fail(ErrorKind::BadInput, describe(f) + ": packed 4:2:2 needs an even width");
      const int stride = f.stride ? f.stride : w * 2;
      MRGI_TRY(need(size_t(stride) * (h - 1) + size_t(w) * 2));
      const bool yuyv = f.format == PixelFormat::YUYV;
      for (int y = 0; y < h; ++y) {
        const uint8_t* s = f.data + size_t(y) * stride;
        uint8_t* d = out.at(0, y);
        for (int x = 0; x < w; x += 2, s += 4, d += 6) {
          const int y0 = yuyv ? s[0] : s[1], y1 = yuyv ? s[2] : s[3];
          const int u = yuyv ? s[1] : s[0], v = yuyv ? s[3] : s[2];
          yuv_to_rgb(y0, u, v, d);
          yuv_to_rgb(y1, u, v, d + 3);
        }
      }
      return ok_status();
    }
    case PixelFormat::RGB24:
    case PixelFormat::BGR24: {
      const int stride = f.stride ? f.stride : w * 3;
      MRGI_TRY(need(size_t(stride) * (h - 1) + size_t(w) * 3));
      for (int y = 0; y < h; ++y) {
        const uint8_t* s = f.data + size_t(y) * stride;
        uint8_t* d = out.at(0, y);
        if (f.format == PixelFormat::RGB24) {
          std::memcpy(d, s, size_t(w) * 3);
        } else {
          for (int x = 0; x < w; ++x) d[3 * x] = s[3 * x + 2], d[3 * x + 1] = s[3 * x + 1], d[3 * x + 2] = s[3 * x];
        }
      }
      return ok_status();
    }
    case PixelFormat::NV12: {
      if (w % 2 || h % 2) return fail(ErrorKind::BadInput, describe(f) + ": 4:2:0 needs an even width and height");
      const int stride = f.stride ? f.stride : w;
      MRGI_TRY(need(size_t(stride) * h + size_t(stride) * (h / 2 - 1) + size_t(w)));
      const uint8_t* uv_plane = f.data + size_t(stride) * h;
      for (int y = 0; y < h; ++y) {
        const uint8_t* ys = f.data + size_t(y) * stride;
        const uint8_t* uv = uv_plane + size_t(y / 2) * stride;
        uint8_t* d = out.at(0, y);
        for (int x = 0; x < w; ++x) yuv_to_rgb(ys[x], uv[x & ~1], uv[(x & ~1) + 1], d + 3 * x);
      }
      return ok_status();
    }
    case PixelFormat::MJPEG:
      return decode_mjpeg(f, out);
  }
  return fail(ErrorKind::BadInput, describe(f) + ": unsupported pixel format");
}

Status copy_yuv(const RawFrame& f, YuvImage& out) {
  const bool nv12 = f.format == PixelFormat::NV12;
  if (!nv12 && f.format != PixelFormat::YUYV)
    return fail(ErrorKind::BadInput, describe(f) + ": only YUYV and NV12 are handed on as Y'CbCr");
  if (f.width <= 0 || f.height <= 0 || f.width > 16384 || f.height > 16384)
    return fail(ErrorKind::BadInput, describe(f) + ": frame size out of range 1..16384");
  if (!f.data) return fail(ErrorKind::BadInput, describe(f) + ": no data");
  if (f.width % 2 || (nv12 && f.height % 2))
    return fail(ErrorKind::BadInput, describe(f) + (nv12 ? ": 4:2:0 needs an even width and height" : ": packed 4:2:2 needs an even width"));
  const size_t row = nv12 ? size_t(f.width) : size_t(f.width) * 2;
  const size_t stride = f.stride ? size_t(f.stride) : row;
  const size_t rows = nv12 ? size_t(f.height) * 3 / 2 : size_t(f.height);
  const size_t needed = stride * (rows - 1) + row;
  if (f.size < needed)
    return fail(ErrorKind::BadInput, describe(f) + ": buffer holds " + std::to_string(f.size) + " bytes, needs " +
                                         std::to_string(needed) + " (short or truncated frame)");
  out.layout = nv12 ? YuvImage::Layout::Nv12 : YuvImage::Layout::Yuyv;
  out.matrix = YuvImage::Matrix::Bt601;
  out.range = YuvImage::Range::Limited;
  out.width = f.width;
  out.height = f.height;
  out.data.resize(row * rows);
  for (size_t r = 0; r < rows; ++r) std::memcpy(out.data.data() + r * row, f.data + r * stride, row);
  return ok_status();
}

std::vector<uint8_t> encode_yuyv(const ImageRGB8& rgb) {
  std::vector<uint8_t> out(size_t(rgb.width) * rgb.height * 2);
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x + 1 < rgb.width; x += 2) {
      int y0, u0, v0, y1, u1, v1;
      rgb_to_yuv(rgb.at(x, y), &y0, &u0, &v0);
      rgb_to_yuv(rgb.at(x + 1, y), &y1, &u1, &v1);
      uint8_t* d = &out[(size_t(y) * rgb.width + x) * 2];
      d[0] = uint8_t(y0), d[1] = uint8_t((u0 + u1 + 1) / 2), d[2] = uint8_t(y1), d[3] = uint8_t((v0 + v1 + 1) / 2);
    }
  return out;
}

std::vector<uint8_t> encode_nv12(const ImageRGB8& rgb) {
  const int w = rgb.width, h = rgb.height;
  std::vector<uint8_t> out(size_t(w) * h * 3 / 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int yy, u, v;
      rgb_to_yuv(rgb.at(x, y), &yy, &u, &v);
      out[size_t(y) * w + x] = uint8_t(yy);
    }
  for (int y = 0; y < h; y += 2)
    for (int x = 0; x < w; x += 2) {
      int su = 0, sv = 0;
      for (int k = 0; k < 4; ++k) {
        int yy, u, v;
        rgb_to_yuv(rgb.at(x + (k & 1), y + (k >> 1)), &yy, &u, &v);
        su += u, sv += v;
      }
      uint8_t* d = &out[size_t(w) * h + size_t(y / 2) * w + x];
      d[0] = uint8_t((su + 2) / 4), d[1] = uint8_t((sv + 2) / 4);
    }
  return out;
}

}  // namespace mrgi
