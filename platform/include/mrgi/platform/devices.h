/// \file
/// Every adapter's view of the machine (for `mrgi devices`) and the source factory with options
/// (for `mrgi live` / `mrgi record`): the plain open_source(SOURCE) of source.h uses the defaults.
#pragma once
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/platform/libcamera.h"
#include "mrgi/platform/openni.h"
#include "mrgi/platform/source.h"
#include "mrgi/platform/usb.h"
#include "mrgi/platform/v4l2.h"

namespace mrgi {

struct DeviceReport {
  Status openni_status = ok_status();     ///< error: OpenNI2 could not initialise
  std::vector<OpenNIDeviceEntry> openni;
  std::vector<V4L2NodeEntry> v4l2;
  Status libcamera_status = ok_status();  ///< error: the camera manager did not start
  std::vector<LibcameraEntry> libcamera;
  UsbScan usb;
};

/// The input adapters and whether this build has each (CMake's MRGI_WITH_<ADAPTER>: on where
/// the package was found at configure). An adapter left out answers every call with NotFound
/// naming its option and package.
struct BuildAdapter {
  const char* name;     ///< openni2, v4l2, libcamera, usb, apriltag
  bool built;
  const char* option;   ///< the CMake option
  const char* package;  ///< the Debian package it needs
};
MRGI_API const std::vector<BuildAdapter>& build_adapters();

/// Asks every adapter; never fails (each adapter's failure is kept in its status).
MRGI_API DeviceReport list_devices_all_adapters();

struct SourceOptions {
  OpenNISettings openni;
  CameraSettings camera;                  ///< v4l2: and libcamera: sources
  /// Optional second stream: a fisheye environment camera, "v4l2:/dev/videoN" or "libcamera:ID".
  /// Its 8-bit frames are decoded to linear radiance (sRGB curve, then divided by env_exposure)
  /// into InputFrame::env, using `env_model` (capture.json "env_camera"), which is also put in
  /// info().env_camera.
  std::string env;
  CameraSettings env_camera;
  std::optional<EnvCamera> env_model;
  double env_exposure = 1.0;              ///< linear radiance -> linear camera value of the env camera
  /// How long next() waits for the env camera after the main frame arrived (ms); when nothing
  /// comes, the last env image is reused (lighting changes slowly), and if there never was one,
  /// the frame has no env image.
  int env_wait_ms = 50;
};

/// SOURCE: a capture folder, "openni:", "openni:FILE.oni", "openni:URI", "v4l2:/dev/videoN",
/// "libcamera:" (first camera) or "libcamera:ID". Unknown prefixes are BadUsage.
MRGI_API Expected<std::unique_ptr<InputSource>> open_source(const std::string& source, const SourceOptions& options);

/// The pairing open_source() does for options.env, for sources opened by other means (tests,
/// embedders): frames of `main` get the newest frame of `env` as InputFrame::env.
MRGI_API std::unique_ptr<InputSource> pair_with_env_camera(std::unique_ptr<InputSource> main, std::unique_ptr<InputSource> env,
                                                  const SourceOptions& options);

struct RecordSettings {
  size_t max_frames = 0;                       ///< 0 = until the stream ends
  std::chrono::milliseconds timeout{3000};     ///< longest wait for one frame
};

/// Reads SOURCE until EndOfStream (or max_frames) and writes capture format v1 to FOLDER with the
/// source's info() as capture.json. Any other error (Timeout, Device, BadInput) stops the
/// recording, removes the partial folder and is returned naming the frame. Returns the frame count.
MRGI_API Expected<size_t> record_to_capture(InputSource& source, const std::string& folder, const RecordSettings& settings);

/// Decodes an 8-bit sRGB env frame to linear radiance: srgb_to_linear(v) / exposure.
MRGI_API void env_frame_to_radiance(const ImageRGB8& frame, double exposure, ImageRGBF& out);

}  // namespace mrgi
