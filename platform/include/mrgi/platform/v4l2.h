/// \file
/// V4L2 cameras through libv4l2 (Debian's libv4l): enumeration of /dev/video*, format
/// negotiation (YUYV, UYVY, RGB24, BGR24, NV12, MJPEG), memory-mapped streaming with select()
/// timeouts, conversion to the runtime's sRGB colour frame. Also the settings shared with the
/// libcamera adapter (CameraSettings).
///
/// Colour-only cameras deliver no depth: InputFrame::depth is a colour-sized image of zeros
/// (0 = no measurement, docs/DESIGN.md), so depth-dependent passes see "nothing measured".
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/platform/source.h"

namespace mrgi {

struct CameraSettings {
  int width = 640;              ///< requested size, pixels; the closest offered size is taken
  int height = 480;
  double fps = 30.0;            ///< requested rate (V4L2: set with VIDIOC_S_PARM when supported)
  /// Pixel format name ("YUYV", "UYVY", "RGB24", "BGR24", "NV12", "MJPEG"); empty = the best
  /// offered, in that order of preference reversed for bandwidth: RGB24, BGR24, YUYV, UYVY,
  /// NV12, MJPEG (uncompressed first: no decode cost, no JPEG artefacts).
  std::string format;
  int buffer_count = 4;         ///< driver buffers (2..16)
  /// Calibrated pinhole intrinsics at the configured size. Without them a pinhole with
  /// `nominal_hfov_deg` horizontal field of view and the principal point at the centre is used,
  /// and the source's name says "uncalibrated".
  std::optional<Intrinsics> intrinsics;
  double nominal_hfov_deg = 60.0;
  double exposure = 1.0;        ///< capture.json exposure to report in info()
  /// YUYV and NV12 frames handed on as the camera delivered them (InputFrame::color_yuv, BT.601
  /// limited range, what UVC and most sensor pipelines send), for the runtime to convert on the
  /// GPU, instead of converted to RGB here; `color` is then empty. For an app whose only reader
  /// of the colour is the runtime. Other formats are converted as before.
  bool yuv_to_runtime = false;
};

struct V4L2FormatEntry {
  std::string fourcc;           ///< as the driver names it
  bool supported = false;       ///< mrgi converts it
  bool emulated = false;        ///< libv4l converts it from another format
  std::vector<std::pair<int, int>> sizes;  ///< discrete sizes (empty = stepwise/continuous)
};

struct V4L2NodeEntry {
  std::string path;             ///< /dev/videoN
  std::string driver, card, bus_info;
  bool capture = false;         ///< single-planar video capture with streaming I/O
  std::vector<V4L2FormatEntry> formats;
  std::string error;            ///< why the node could not be queried (permissions, busy)
};

/// Lists /dev/video* (sorted). An absent /dev or no nodes is an empty list, not an error.
MRGI_API std::vector<V4L2NodeEntry> list_v4l2_nodes();

/// Opens DEVICE (/dev/videoN) and starts streaming. NotFound when the node is absent,
/// BadInput when it offers no format mrgi converts (the message lists what it offers), Device
/// for driver failures.
MRGI_API Expected<std::unique_ptr<InputSource>> open_v4l2_source(const std::string& device,
                                                        const CameraSettings& settings = {});

}  // namespace mrgi
