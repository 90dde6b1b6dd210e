// The source dispatcher and the environment-camera pairing.
#include <filesystem>

#include "mrgi/metrics.h"
#include "mrgi/platform/devices.h"
#include "mrgi/platform/capture_source.h"

namespace mrgi {
namespace {

using Clock = std::chrono::steady_clock;

// Pairs the main source's frames with the latest frame of a second (environment) camera.
class EnvPairedSource final : public InputSource {
 public:
  EnvPairedSource(std::unique_ptr<InputSource> main, std::unique_ptr<InputSource> env, const SourceOptions& o)
      : main_(std::move(main)), env_(std::move(env)), exposure_(o.env_exposure), wait_(o.env_wait_ms) {
    info_ = main_->info();
    info_.env_camera = o.env_model;
    name_ = main_->name() + " + env " + env_->name();
  }
  std::string name() const override { return name_; }
  const CaptureInfo& info() const override { return info_; }

  Expected<InputFrame> next(std::chrono::milliseconds timeout) override {
    auto frame = main_->next(timeout);
    if (!frame.ok()) return frame;
    // Drain what the env camera has, keeping the newest; wait briefly only when there is none.
    auto env = env_->next(std::chrono::milliseconds(have_env_ ? 0 : wait_));
    while (env.ok()) {
      env_frame_to_radiance(env->color, exposure_, radiance_);
      have_env_ = true;
      env = env_->next(std::chrono::milliseconds(0));
    }
    if (env.error().kind != ErrorKind::Timeout)
      return fail(env.error().kind, "environment camera: " + env.error().message);
    if (have_env_) frame->env = radiance_;
    return frame;
  }

 private:
  std::unique_ptr<InputSource> main_, env_;
  double exposure_;
  int wait_;
  std::string name_;
  CaptureInfo info_;
  ImageRGBF radiance_;
  bool have_env_ = false;
};

Expected<std::unique_ptr<InputSource>> open_camera_like(const std::string& source, const CameraSettings& camera,
                                                        const SourceOptions& options) {
  if (source.rfind("v4l2:", 0) == 0) {
    const std::string dev = source.substr(5);
    if (dev.empty()) return fail(ErrorKind::BadUsage, "v4l2: needs a device node, e.g. v4l2:/dev/video0");
    return open_v4l2_source(dev, camera);
  }
  if (source.rfind("libcamera:", 0) == 0) return open_libcamera_source(source.substr(10), camera);
  if (source.rfind("openni:", 0) == 0) return open_openni_source(source.substr(7), options.openni);
  return fail(ErrorKind::BadUsage, "'" + source + "': unknown source (use a capture folder, openni:, openni:FILE.oni, "
                                                  "v4l2:/dev/videoN or libcamera:ID)");
}

}  // namespace

void env_frame_to_radiance(const ImageRGB8& frame, double exposure, ImageRGBF& out) {
  if (out.width != frame.width || out.height != frame.height) out = ImageRGBF(frame.width, frame.height);
  const float inv = float(1.0 / (exposure > 0.0 ? exposure : 1.0));
  for (size_t i = 0; i < frame.data.size(); ++i) out.data[i] = srgb8_to_linear(frame.data[i]) * inv;
}

Expected<std::unique_ptr<InputSource>> open_source(const std::string& source, const SourceOptions& options) {
  std::unique_ptr<InputSource> main;
  if (source.find(':') == std::string::npos || std::filesystem::is_directory(source)) {
    auto s = make_capture_source(source);
    if (!s.ok()) return s.error();
    main = std::move(s.value());
  } else {
    auto s = open_camera_like(source, options.camera, options);
    if (!s.ok()) return s.error();
    main = std::move(s.value());
  }
  if (options.env.empty()) return main;
  if (options.env.rfind("v4l2:", 0) != 0 && options.env.rfind("libcamera:", 0) != 0)
    return fail(ErrorKind::BadUsage, "--env '" + options.env + "': the environment camera must be v4l2:/dev/videoN or libcamera:ID");
  if (!options.env_model || options.env_model->model != EnvModel::FisheyeEquidistant || options.env_model->f <= 0.0)
    return fail(ErrorKind::BadUsage, "--env " + options.env + ": needs a calibrated fisheye model (capture.json env_camera: "
                                     "model fisheye_equidistant with f > 0, cx, cy, fov_deg)");
  auto env = open_camera_like(options.env, options.env_camera, options);
  if (!env.ok()) return fail(env.error().kind, "environment camera: " + env.error().message);
  return pair_with_env_camera(std::move(main), std::move(env.value()), options);
}

std::unique_ptr<InputSource> pair_with_env_camera(std::unique_ptr<InputSource> main, std::unique_ptr<InputSource> env,
                                                  const SourceOptions& options) {
  return std::make_unique<EnvPairedSource>(std::move(main), std::move(env), options);
}

Expected<std::unique_ptr<InputSource>> open_source(const std::string& source) { return open_source(source, SourceOptions{}); }

}  // namespace mrgi
