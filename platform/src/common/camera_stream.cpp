#include "common/camera_stream.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace mrgi {
namespace {

int preference_rank(PixelFormat f) {
  switch (f) {
    case PixelFormat::RGB24: return 0;
    case PixelFormat::BGR24: return 1;
    case PixelFormat::YUYV: return 2;
    case PixelFormat::UYVY: return 3;
    case PixelFormat::NV12: return 4;
    case PixelFormat::MJPEG: return 5;
  }
  return 9;
}

std::string supported_list() { return "YUYV, UYVY, RGB24, BGR24, NV12, MJPEG"; }

}  // namespace

const char* to_string(CameraState s) {
  switch (s) {
    case CameraState::Closed: return "closed";
    case CameraState::Opened: return "opened";
    case CameraState::Configured: return "configured";
    case CameraState::Streaming: return "streaming";
    case CameraState::Lost: return "lost";
  }
  return "?";
}

Intrinsics nominal_intrinsics(int width, int height, double hfov_deg) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 0.5 * width / std::tan(0.5 * hfov_deg * M_PI / 180.0);
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

Expected<FormatOption> choose_format(const OfferedFormats& offered, const CameraSettings& settings,
                                     const std::string& device) {
  if (offered.supported.empty()) {
    std::string names;
    for (const auto& n : offered.unsupported) names += (names.empty() ? "" : ", ") + n;
    return fail(ErrorKind::BadInput, device + ": unsupported format: the device offers " +
                                         (names.empty() ? std::string("no formats") : names) +
                                         "; mrgi converts " + supported_list());
  }
  const FormatOption* best = nullptr;
  long best_cost = 0;
  for (const FormatOption& o : offered.supported) {
    if (!settings.format.empty() && settings.format != to_string(o.format)) continue;
    const long cost = (std::labs(o.width - settings.width) + std::labs(o.height - settings.height)) * 16 +
                      preference_rank(o.format);
    if (!best || cost < best_cost) best = &o, best_cost = cost;
  }
  if (!best)
    return fail(ErrorKind::BadInput, device + ": unsupported format: requested pixel format '" + settings.format +
                                         "' is not offered by the device");
  return *best;
}

CameraStreamSource::CameraStreamSource(std::unique_ptr<CameraBackend> backend, const CameraSettings& settings)
    : backend_(std::move(backend)), settings_(settings), name_(backend_->name()) {}

CameraStreamSource::~CameraStreamSource() { shut_down(CameraState::Closed); }

void CameraStreamSource::shut_down(CameraState final_state) {
  // Backends' stop() and close() are idempotent, so a half-opened device is released too.
  if (state_ != CameraState::Closed && state_ != CameraState::Lost) {
    backend_->stop();
    backend_->close();
  }
  state_ = final_state;
}

Expected<std::unique_ptr<CameraStreamSource>> CameraStreamSource::open(std::unique_ptr<CameraBackend> backend,
                                                                       const CameraSettings& settings) {
  if (settings.buffer_count < 2 || settings.buffer_count > 16)
    return fail(ErrorKind::BadUsage, backend->name() + ": buffer_count " + std::to_string(settings.buffer_count) +
                                         " is outside 2..16");
  if (settings.width <= 0 || settings.height <= 0)
    return fail(ErrorKind::BadUsage, backend->name() + ": requested size must be positive");
  auto src = std::unique_ptr<CameraStreamSource>(new CameraStreamSource(std::move(backend), settings));
  auto st = src->start_stream();
  if (!st.ok()) {
    src->shut_down(CameraState::Closed);
    return st.error();
  }
  return src;
}

Status CameraStreamSource::start_stream() {
  MRGI_TRY(backend_->open());
  state_ = CameraState::Opened;
  auto offered = backend_->formats();
  if (!offered.ok()) return offered.error();
  auto chosen = choose_format(*offered, settings_, name_);
  if (!chosen.ok()) return chosen.error();
  auto actual = backend_->configure(*chosen, settings_);
  if (!actual.ok()) return actual.error();
  format_ = *actual;
  if (format_.width <= 0 || format_.height <= 0)
    return fail(ErrorKind::Device, name_ + ": the driver configured an empty size");
  state_ = CameraState::Configured;
  info_ = CaptureInfo{};
  if (settings_.intrinsics) {
    if (settings_.intrinsics->width != format_.width || settings_.intrinsics->height != format_.height)
      info_.color = settings_.intrinsics->scaled_to(format_.width, format_.height);
    else
      info_.color = *settings_.intrinsics;
  } else {
    info_.color = nominal_intrinsics(format_.width, format_.height, settings_.nominal_hfov_deg);
    name_ += " (uncalibrated: nominal " + std::to_string(int(settings_.nominal_hfov_deg)) + " deg hfov)";
  }
  info_.depth = info_.color;
  info_.exposure = settings_.exposure;
  color_ = ImageRGB8(format_.width, format_.height);
  MRGI_TRY(backend_->start());
  state_ = CameraState::Streaming;
  return ok_status();
}

Expected<InputFrame> CameraStreamSource::next(std::chrono::milliseconds timeout) {
  if (state_ == CameraState::Lost)
    return fail(ErrorKind::Device, name_ + ": the stream was lost earlier (" + lost_reason_ + ")");
  if (state_ != CameraState::Streaming)
    return fail(ErrorKind::EndOfStream, name_ + ": the stream is " + to_string(state_));
  auto raw = backend_->dequeue(timeout);
  if (!raw.ok()) {
    const Error& e = raw.error();
    if (e.kind == ErrorKind::Device) {
      lost_reason_ = e.message;
      shut_down(CameraState::Lost);
    } else if (e.kind == ErrorKind::EndOfStream) {
      shut_down(CameraState::Closed);
    }
    return e;
  }
  RawFrame frame = *raw;
  if (frame.width != format_.width || frame.height != format_.height || frame.format != format_.format) {
    (void)backend_->release();
    return fail(ErrorKind::BadInput, name_ + ": frame " + std::to_string(frame.sequence) + " is " +
                                         to_string(frame.format) + " " + std::to_string(frame.width) + "x" +
                                         std::to_string(frame.height) + ", the stream was configured as " +
                                         to_string(format_.format) + " " + std::to_string(format_.width) + "x" +
                                         std::to_string(format_.height));
  }
  const bool pass_yuv =
      settings_.yuv_to_runtime && (frame.format == PixelFormat::YUYV || frame.format == PixelFormat::NV12);
  InputFrame out;
  const Status converted = pass_yuv ? copy_yuv(frame, out.color_yuv.emplace()) : convert_to_rgb8(frame, color_);
  const Status released = backend_->release();
  if (!converted.ok()) return fail(converted.error().kind, name_ + ": " + converted.error().message);
  if (!released.ok()) {
    lost_reason_ = released.error().message;
    shut_down(CameraState::Lost);
    return released.error();
  }
  out.index = emitted_++;
  out.timestamp = frame.timestamp;
  out.depth_timestamp = frame.timestamp;
  if (!pass_yuv) out.color = color_;
  out.depth = ImageU16(color_.width, color_.height, 0);  // colour-only camera: nothing measured
  return out;
}

}  // namespace mrgi
