/// \file
/// libcamera cameras (Debian's libcamera 0.0.3 API): CameraManager, Camera::acquire/configure,
/// FrameBufferAllocator, Request queueing and the requestCompleted signal, converted to the
/// runtime's sRGB colour frame. Colour-only, like V4L2 (depth is zeros, see v4l2.h).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/platform/source.h"
#include "mrgi/platform/v4l2.h"

namespace mrgi {

struct LibcameraEntry {
  std::string id;         ///< what libcamera:ID takes
  std::string model;      ///< properties::Model, when the pipeline reports it
  std::string location;   ///< front / back / external, when reported
};

/// Cameras libcamera's pipeline handlers manage now. Starting the camera manager failing is an
/// error (Device); no camera is an empty list.
MRGI_API Expected<std::vector<LibcameraEntry>> list_libcamera_cameras();

/// Opens camera ID (empty = the first) and starts streaming. NotFound when absent.
MRGI_API Expected<std::unique_ptr<InputSource>> open_libcamera_source(const std::string& id,
                                                             const CameraSettings& settings = {});

}  // namespace mrgi
