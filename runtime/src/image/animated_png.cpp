// APNG (https://wiki.mozilla.org/APNG_Specification): IHDR, acTL (frame count, loops), then per
// frame an fcTL (size, offset, delay) and its image data: IDAT for the first frame, which is also
// the still image a plain PNG reader shows, fdAT (a sequence number, then the same zlib stream)
// for the others. Written chunk by chunk as frames arrive, so a clip never sits in memory.
#include "mrgi/animated_png.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "image/file_io.h"

namespace mrgi {
namespace {

void put32(std::vector<uint8_t>& v, uint32_t x) {
  v.push_back(uint8_t(x >> 24));
  v.push_back(uint8_t(x >> 16));
  v.push_back(uint8_t(x >> 8));
  v.push_back(uint8_t(x));
}
void put16(std::vector<uint8_t>& v, uint16_t x) {
  v.push_back(uint8_t(x >> 8));
  v.push_back(uint8_t(x));
}

// A frame's scanlines with PNG's Paeth filter (the best of the five on camera images and
// renders alike, and one filter keeps the encoder simple), deflated at zlib level 3 (as
// write_png's Fast).
Expected<std::vector<uint8_t>> encode_frame(const uint8_t* pixels, int channels, int width, int height) {
  const size_t row = size_t(width) * 3;
  std::vector<uint8_t> filtered((row + 1) * size_t(height));
  std::vector<uint8_t> prev(row, 0), cur(row);
  for (int y = 0; y < height; ++y) {
    const uint8_t* src = pixels + size_t(y) * size_t(width) * size_t(channels);
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) cur[size_t(x) * 3 + size_t(c)] = src[size_t(x) * size_t(channels) + size_t(c)];
    uint8_t* out = &filtered[size_t(y) * (row + 1)];
    out[0] = 4;  // Paeth
    for (size_t i = 0; i < row; ++i) {
      const int a = i >= 3 ? cur[i - 3] : 0, b = prev[i], c = i >= 3 ? prev[i - 3] : 0;
      const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
      const int pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
      out[1 + i] = uint8_t(cur[i] - pred);
    }
    std::swap(prev, cur);
  }
  uLongf size = compressBound(uLong(filtered.size()));
  std::vector<uint8_t> z(size);
  if (compress2(z.data(), &size, filtered.data(), uLong(filtered.size()), 3) != Z_OK)
    return fail(ErrorKind::Internal, "animated PNG: zlib could not compress a frame");
  z.resize(size);
  return z;
}

}  // namespace

Expected<AnimatedPngWriter> AnimatedPngWriter::create(const std::string& path, int width, int height, double fps) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    return fail(ErrorKind::BadUsage, path + ": animated PNG size " + std::to_string(width) + "x" +
                                         std::to_string(height) + " is outside 1..16384");
  if (!std::isfinite(fps) || fps < 0.1 || fps > 1000.0)
    return fail(ErrorKind::BadUsage, path + ": animated PNG rate " + std::to_string(fps) + " fps is outside 0.1..1000");
  AnimatedPngWriter w;
  w.path_ = path;
  w.partial_ = path + ".partial";
  w.width_ = width;
  w.height_ = height;
  // The delay as a fraction with a 1000 denominator (APNG's fields are 16-bit).
  w.delay_num_ = uint16_t(std::max(1.0, std::round(1000.0 / fps)));
  w.delay_den_ = 1000;
  w.file_ = std::fopen(w.partial_.c_str(), "wb");
  if (!w.file_) return fail(ErrorKind::BadInput, w.partial_ + ": cannot open for writing: " + std::strerror(errno));
  static const uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  if (std::fwrite(signature, 1, 8, w.file_) != 8) return fail(ErrorKind::BadInput, w.partial_ + ": write failed");
  std::vector<uint8_t> ihdr;
  put32(ihdr, uint32_t(width));
  put32(ihdr, uint32_t(height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit RGB, deflate, adaptive filtering, no interlace
  MRGI_TRY(w.chunk("IHDR", ihdr.data(), ihdr.size()));
  w.actl_offset_ = std::ftell(w.file_) + 8;  // past the length and type
  std::vector<uint8_t> actl;
  put32(actl, 0);  // frames: patched by finish()
  put32(actl, 0);  // loop forever
  MRGI_TRY(w.chunk("acTL", actl.data(), actl.size()));
  return w;
}

AnimatedPngWriter::AnimatedPngWriter(AnimatedPngWriter&& o) noexcept
    : path_(std::move(o.path_)), partial_(std::move(o.partial_)), file_(o.file_), width_(o.width_),
      height_(o.height_), delay_num_(o.delay_num_), delay_den_(o.delay_den_), frames_(o.frames_),
      sequence_(o.sequence_), actl_offset_(o.actl_offset_) {
  o.file_ = nullptr;
}

AnimatedPngWriter::~AnimatedPngWriter() {
  if (file_) {  // never finished: nothing is left behind
    std::fclose(file_);
    std::remove(partial_.c_str());
  }
}

Status AnimatedPngWriter::chunk(const char type[4], const uint8_t* data, size_t size) {
  if (!file_) return fail(ErrorKind::BadUsage, path_ + ": animated PNG already finished");
  std::vector<uint8_t> head;
  put32(head, uint32_t(size));
  head.insert(head.end(), type, type + 4);
  uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(type), 4);
  if (size > 0) crc = crc32(crc, data, uInt(size));
  std::vector<uint8_t> tail;
  put32(tail, uint32_t(crc));
  if (std::fwrite(head.data(), 1, head.size(), file_) != head.size() ||
      (size > 0 && std::fwrite(data, 1, size, file_) != size) ||
      std::fwrite(tail.data(), 1, tail.size(), file_) != tail.size())
    return fail(ErrorKind::BadInput, partial_ + ": write failed (disk full?)");
  return ok_status();
}

Status AnimatedPngWriter::add_rows(const uint8_t* pixels, int channels) {
  std::vector<uint8_t> fctl;
  put32(fctl, sequence_++);
  put32(fctl, uint32_t(width_));
  put32(fctl, uint32_t(height_));
  put32(fctl, 0);
  put32(fctl, 0);
  put16(fctl, delay_num_);
  put16(fctl, delay_den_);
  fctl.insert(fctl.end(), {0, 0});  // dispose none, blend source: each frame replaces the last
  MRGI_TRY(chunk("fcTL", fctl.data(), fctl.size()));
  auto z = encode_frame(pixels, channels, width_, height_);
  if (!z) return z.error();
  if (frames_ == 0) {
    MRGI_TRY(chunk("IDAT", z->data(), z->size()));
  } else {
    std::vector<uint8_t> fdat;
    fdat.reserve(z->size() + 4);
    put32(fdat, sequence_++);
    fdat.insert(fdat.end(), z->begin(), z->end());
    MRGI_TRY(chunk("fdAT", fdat.data(), fdat.size()));
  }
  ++frames_;
  return ok_status();
}

Status AnimatedPngWriter::add(const ImageRGBA8& frame) {
  if (frame.width != width_ || frame.height != height_)
    return fail(ErrorKind::BadUsage, path_ + ": frame of " + std::to_string(frame.width) + "x" +
                                         std::to_string(frame.height) + " in a clip of " + std::to_string(width_) +
                                         "x" + std::to_string(height_));
  return add_rows(frame.data.data(), 4);
}

Status AnimatedPngWriter::add(const ImageRGB8& frame) {
  if (frame.width != width_ || frame.height != height_)
    return fail(ErrorKind::BadUsage, path_ + ": frame of " + std::to_string(frame.width) + "x" +
                                         std::to_string(frame.height) + " in a clip of " + std::to_string(width_) +
                                         "x" + std::to_string(height_));
  return add_rows(frame.data.data(), 3);
}

Status AnimatedPngWriter::finish() {
  if (!file_) return fail(ErrorKind::BadUsage, path_ + ": animated PNG already finished");
  if (frames_ == 0) return fail(ErrorKind::BadUsage, path_ + ": animated PNG without a frame");
  MRGI_TRY(chunk("IEND", nullptr, 0));
  // acTL's frame count, and its CRC, now that the count is known.
  std::vector<uint8_t> actl;
  put32(actl, frames_);
  put32(actl, 0);
  uLong crc = crc32(0L, reinterpret_cast<const Bytef*>("acTL"), 4);
  crc = crc32(crc, actl.data(), uInt(actl.size()));
  put32(actl, uint32_t(crc));
  const bool ok = std::fseek(file_, actl_offset_, SEEK_SET) == 0 &&
                  std::fwrite(actl.data(), 1, actl.size(), file_) == actl.size();
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) {
    std::remove(partial_.c_str());
    return fail(ErrorKind::BadInput, partial_ + ": write failed (disk full?)");
  }
  return rename_into_place(partial_, path_);
}

}  // namespace mrgi
