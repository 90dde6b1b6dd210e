/// \file
/// A clip of frames as an animated PNG (APNG: the PNG extension browsers, ffmpeg and Pillow
/// play; a viewer without it shows the first frame). What `mrgi replay --video` writes where no
/// video encoder is present: lossless, so it shows exactly the frames mrgi made.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/image.h"

namespace mrgi {

class MRGI_API AnimatedPngWriter {
 public:
  /// Frames of width x height shown at `fps` (0.1..1000), looping. Writes PATH.partial and
  /// renames it to PATH in finish(): a failed or abandoned clip leaves no file behind.
  static Expected<AnimatedPngWriter> create(const std::string& path, int width, int height, double fps);
  AnimatedPngWriter(AnimatedPngWriter&& o) noexcept;
  AnimatedPngWriter& operator=(AnimatedPngWriter&&) = delete;
  AnimatedPngWriter(const AnimatedPngWriter&) = delete;
  ~AnimatedPngWriter();
  /// Appends a frame (alpha dropped: the composite is opaque). BadUsage for another size.
  Status add(const ImageRGBA8& frame);
  Status add(const ImageRGB8& frame);
  /// Writes the frame count and renames the file into place. BadUsage with no frame.
  Status finish();
  uint32_t frames() const { return frames_; }

 private:
  AnimatedPngWriter() = default;
  Status add_rows(const uint8_t* pixels, int channels);
  Status chunk(const char type[4], const uint8_t* data, size_t size);
  std::string path_, partial_;
  std::FILE* file_ = nullptr;
  int width_ = 0, height_ = 0;
  uint16_t delay_num_ = 1, delay_den_ = 30;
  uint32_t frames_ = 0;
  uint32_t sequence_ = 0;   ///< APNG's fcTL/fdAT sequence number
  long actl_offset_ = 0;    ///< where acTL's frame count is, patched by finish()
};

}  // namespace mrgi
