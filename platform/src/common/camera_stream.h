// The streaming-camera state machine shared by V4L2 and libcamera, written against a small
// backend interface so that it is tested on recorded buffers (no device exists on CI):
//
//   Closed --open--> Opened --configure--> Configured --start--> Streaming
//   Streaming --next: frame/Timeout--> Streaming      Streaming --Device error (unplug)--> Lost
//   Streaming --EndOfStream--> Closed (recorded backends)   Lost/Closed --next--> named error
#pragma once
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "common/pixel_convert.h"
#include "mrgi/platform/v4l2.h"

namespace mrgi {

struct FormatOption {
  PixelFormat format = PixelFormat::YUYV;
  int width = 0, height = 0;
};

// What a device offers: formats mrgi converts, and the names of those it does not (for errors).
struct OfferedFormats {
  std::vector<FormatOption> supported;
  std::vector<std::string> unsupported;
};

class CameraBackend {
 public:
  virtual ~CameraBackend() = default;
  virtual std::string name() const = 0;                 // "v4l2:/dev/video0", "libcamera:ID"
  virtual Status open() = 0;                            // NotFound when the device is absent
  virtual Expected<OfferedFormats> formats() = 0;
  // Applies `wanted`; returns what the device actually set (it may adjust the size).
  virtual Expected<FormatOption> configure(const FormatOption& wanted, const CameraSettings& settings) = 0;
  virtual Status start() = 0;
  // Waits at most `timeout` for a filled buffer. The view stays valid until release().
  // Timeout: nothing arrived; Device: the device failed or was unplugged; EndOfStream: a recorded
  // backend has no more buffers.
  virtual Expected<RawFrame> dequeue(std::chrono::milliseconds timeout) = 0;
  virtual Status release() = 0;                         // gives the dequeued buffer back
  virtual void stop() = 0;                              // idempotent
  virtual void close() = 0;                             // idempotent
};

enum class CameraState { Closed, Opened, Configured, Streaming, Lost };
const char* to_string(CameraState s);

// Chooses among offered formats: an explicit format name must be offered; then the closest size
// (sum of absolute differences), then the preference order of CameraSettings::format.
Expected<FormatOption> choose_format(const OfferedFormats& offered, const CameraSettings& settings,
                                     const std::string& device);

class CameraStreamSource final : public InputSource {
 public:
  static Expected<std::unique_ptr<CameraStreamSource>> open(std::unique_ptr<CameraBackend> backend,
                                                            const CameraSettings& settings);
  ~CameraStreamSource() override;
  std::string name() const override { return name_; }
  const CaptureInfo& info() const override { return info_; }
  Expected<InputFrame> next(std::chrono::milliseconds timeout) override;
  CameraState state() const { return state_; }
  const FormatOption& format() const { return format_; }

 private:
  CameraStreamSource(std::unique_ptr<CameraBackend> backend, const CameraSettings& settings);
  Status start_stream();
  void shut_down(CameraState final_state);

  std::unique_ptr<CameraBackend> backend_;
  CameraSettings settings_;
  std::string name_;
  CaptureInfo info_;
  CameraState state_ = CameraState::Closed;
  FormatOption format_;
  std::string lost_reason_;
  ImageRGB8 color_;
  int64_t emitted_ = 0;
};

// Nominal pinhole for an uncalibrated camera: hfov_deg horizontally, square pixels, centred.
Intrinsics nominal_intrinsics(int width, int height, double hfov_deg);

}  // namespace mrgi

namespace mrgi {
// The real device backends (v4l2/, libcamera/), exposed for the listing and the dispatcher.
std::unique_ptr<CameraBackend> make_v4l2_backend(const std::string& device);
std::unique_ptr<CameraBackend> make_libcamera_backend(const std::string& camera_id);
}  // namespace mrgi
