/// \file
/// One input interface for every source (modelled on InfiniTAM's ImageSourceEngine):
/// capture replay, OpenNI2 (live and .oni), V4L2, libcamera. "A frame is ready now" is kept
/// apart from "the stream ended", and every wait is bounded: a sensor that stops sending
/// gives ErrorKind::Timeout, never a hang.
#pragma once
#include <chrono>
#include <memory>
#include <string>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/frame.h"
#include "mrgi/platform/capture.h"

namespace mrgi {

class MRGI_API InputSource {
 public:
  virtual ~InputSource() = default;
  virtual std::string name() const = 0;          ///< e.g. "openni:/path/x.oni"
  virtual const CaptureInfo& info() const = 0;   ///< intrinsics, depth scale, exposure
  /// Blocks at most `timeout`. Returns the next frame, or an Error of kind EndOfStream (stream
  /// finished normally), Timeout (nothing arrived in time) or Device/BadInput.
  virtual Expected<InputFrame> next(std::chrono::milliseconds timeout) = 0;
};

/// Opens SOURCE: a capture folder path, "openni:", "openni:FILE.oni", "v4l2:/dev/videoN",
/// "libcamera:ID". Adapters that are not built or whose device is absent return NotFound
/// with the adapter's name.
MRGI_API Expected<std::unique_ptr<InputSource>> open_source(const std::string& source);

}  // namespace mrgi
