// The camera frame as the host's readers see it: the light stage's estimates from colour and
// depth (probeless and residual light, the environment's unseen prior and near-field test) and
// the techniques' reuse tests (gi/input_reuse.h, ssrt's fusion skip). They read it sparsely or
// once, on the host, while the frame is recorded.
//
// Where the images come from:
//   - this frame's InputFrame (CameraView::of), for a frame given in host memory;
//   - the runtime's own upload buffers of the frame slot about to be reused, which hold the frame
//     last recorded in that slot (written by the host's upload or, for a frame given as the app's
//     images, by the GPU's copy), with that frame's index, timestamp and pose: in a steady stream
//     the frame frames_in_flight frames earlier; a priming run (Runtime::process) fills a slot
//     with the frame it primes, so just after one the lag is shorter. The host never sees a frame
//     given as the app's images, so its readers take this view (RuntimeSettings::
//     lagged_camera_reads selects it for host-memory frames too); a slot not yet used has no
//     images (empty()).
// The view points into memory it does not own, valid while the frame is recorded.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "mrgi/frame.h"

namespace mrgi::frame {

// Depth rows of `width` u16 values (depth units, 0 = invalid), tightly packed.
struct DepthView {
  const uint16_t* data = nullptr;
  int width = 0, height = 0;
  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  size_t size() const { return empty() ? 0 : size_t(width) * size_t(height); }
  uint16_t at(int x, int y) const { return data[size_t(y) * size_t(width) + size_t(x)]; }
  const uint16_t* row(int y) const { return data + size_t(y) * size_t(width); }
};

struct CameraView {
  int64_t index = 0;        // the frame these images are (InputFrame::index)
  double timestamp = 0.0;   // its colour timestamp, seconds
  // The frame being recorded (its index and timestamp; the same as above unless lagged): what
  // light from this frame's own inputs (its environment image, the lamps) is stamped with.
  int64_t frame_index = 0;
  double frame_timestamp = 0.0;
  glm::dmat4 camera_to_world{1.0};  // its pose (the runtime's rule: the last known one when none)
  // Colour: sRGB8 rows (R, G, B bytes first in each pixel's rgb_stride bytes, tightly packed:
  // 3 for an InputFrame's image, 4 for the runtime's upload words), or the Y'CbCr frame as
  // delivered (light/camera_color.h decodes the pixels it reads); at most one is set.
  const uint8_t* rgb = nullptr;
  int rgb_stride = 3;
  const YuvImage* yuv = nullptr;
  int color_width = 0, color_height = 0;
  DepthView depth;
  // This frame's environment image (InputFrame::env: host data, never lagged), if any.
  const ImageRGBF* env = nullptr;

  bool has_color() const { return (rgb != nullptr || yuv != nullptr) && color_width > 0 && color_height > 0; }
  // No images at all: the first frames of a lagged view.
  bool empty() const { return !has_color() && depth.empty(); }

  // The view of a frame given in host memory, at `camera_to_world`.
  static CameraView of(const InputFrame& frame, const glm::dmat4& camera_to_world) {
    CameraView v;
    v.index = v.frame_index = frame.index;
    v.timestamp = v.frame_timestamp = frame.timestamp;
    v.camera_to_world = camera_to_world;
    if (frame.color_yuv) {
      v.yuv = &*frame.color_yuv;
      v.color_width = frame.color_yuv->width;
      v.color_height = frame.color_yuv->height;
    } else if (!frame.color.data.empty()) {
      v.rgb = frame.color.data.data();
      v.color_width = frame.color.width;
      v.color_height = frame.color.height;
    }
    if (!frame.depth.data.empty()) v.depth = DepthView{frame.depth.data.data(), frame.depth.width, frame.depth.height};
    v.env = frame.env ? &*frame.env : nullptr;
    return v;
  }
};

}  // namespace mrgi::frame
