// `mrgi replay --video FILE`: the composited frames as a clip a user can watch.
//   FILE.png / FILE.apng  an animated PNG (mrgi/animated_png.h), lossless, always available;
//   FILE.mp4 / .mkv / .webm  encoded by Debian's `ffmpeg` program (H.264 / VP9) when it is on
//                          PATH; without it the command refuses before replaying anything.
// The clip is written to FILE.partial and renamed to FILE when the replay succeeds.
#pragma once
#include <cstdio>
#include <optional>
#include <string>

#include "mrgi/animated_png.h"
#include "mrgi/expected.h"
#include "mrgi/image.h"

namespace mrgi::tool {

class VideoOutput {
 public:
  // Checks the name and the encoder (BadUsage naming what is missing); writes nothing yet.
  static Status check(const std::string& path, const std::string& out_dir);
  static Expected<VideoOutput> create(const std::string& path, int width, int height, double fps);
  VideoOutput(VideoOutput&& o) noexcept;
  VideoOutput& operator=(VideoOutput&&) = delete;
  ~VideoOutput();
  Status add(const ImageRGBA8& frame);
  Status finish();

 private:
  VideoOutput() = default;
  std::string path_, partial_;
  int width_ = 0, height_ = 0;
  std::optional<AnimatedPngWriter> apng_;
  std::FILE* pipe_ = nullptr;  // ffmpeg's standard input (raw RGBA frames)
};

// Frames per second of a capture from its colour timestamps (the median interval), 30 when
// they do not say (fewer than two frames, equal stamps).
double capture_fps(const std::vector<double>& timestamps);

}  // namespace mrgi::tool
