/// \file
/// One input frame, as every source delivers it: capture replay, OpenNI2, V4L2, libcamera.
/// Conventions (docs/DESIGN.md): camera is OpenCV/TUM (x right, y down, looking along +z); poses are
/// camera-to-world; world is right-handed, metres, +y up.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/glm_contract.h"

#include "mrgi/image.h"

namespace mrgi {

/// Pinhole intrinsics in pixels for an image of width x height.
struct MRGI_API Intrinsics {
  int width = 640;
  int height = 480;
  double fx = 517.3, fy = 516.5, cx = 318.6, cy = 255.3;  ///< TUM Freiburg 1 defaults
  /// The same camera at another resolution (fx, cx scale with width; fy, cy with height).
  Intrinsics scaled_to(int w, int h) const;
};

/// Rigid camera-to-world transform.
struct MRGI_API Pose {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  ///< w, x, y, z (glm order); unit length
  glm::dmat4 matrix() const;                  ///< camera-to-world
};

/// Environment camera models (capture.json "env_camera").
enum class EnvModel { Equirectangular, FisheyeEquidistant };
struct EnvCamera {
  EnvModel model = EnvModel::Equirectangular;
  /// Fisheye only: equidistant model r = f * theta (f in pixels, theta from the optical axis),
  /// centre (cx, cy) in pixels; fov_deg is the full field of view of the image circle.
  double f = 0.0, cx = 0.0, cy = 0.0, fov_deg = 180.0;
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  ///< env camera to world (fisheye looks along its +z)
  /// Where the env camera is (world metres), when known: declared lamps it sees are then removed
  /// from its images (they would be counted twice, light/lamp_removal.h). Absent: only
  /// directional lamps (a declared sun) can be found in the image.
  std::optional<glm::dvec3> position;
};

/// A colour frame as a camera delivers it in Y'CbCr (V4L2, libcamera, Android's Camera2): the
/// runtime converts it to the camera's R'G'B' (taken as sRGB) on the GPU, so the app hands its
/// buffer over without a conversion of its own. 8 bits a sample, tightly packed rows. The
/// conversion is a compute pass on every device (a sampler Y'CbCr conversion, where a device has
/// one, is not used); the chroma of a pixel is its pair's (YUYV) or its 2 x 2 block's (NV12).
struct YuvImage {
  enum class Layout {
    Nv12,  ///< 4:2:0: the Y' plane (width x height bytes), then Cb Cr interleaved at half size each way
    Yuyv,  ///< 4:2:2 packed: Y'0 Cb Y'1 Cr for each pair of pixels (width x 2 bytes a row)
  };
  enum class Matrix {
    Bt601,  ///< SD video and most webcams (Kr 0.299, Kb 0.114)
    Bt709,  ///< HD video (Kr 0.2126, Kb 0.0722)
  };
  enum class Range {
    Limited,  ///< Y' 16-235, Cb Cr 16-240 (video)
    Full,     ///< 0-255 each (JPEG / JFIF)
  };
  Layout layout = Layout::Nv12;
  Matrix matrix = Matrix::Bt601;
  Range range = Range::Limited;
  int width = 0, height = 0;  ///< even; the colour intrinsics' size
  std::vector<uint8_t> data;  ///< NV12: width x height x 3 / 2 bytes; YUYV: width x height x 2
  /// Bytes `data` must hold for this layout and size.
  size_t expected_bytes() const {
    return layout == Layout::Nv12 ? size_t(width) * size_t(height) * 3 / 2 : size_t(width) * size_t(height) * 2;
  }
};

struct InputFrame {
  int64_t index = 0;          ///< frame number in the stream, from 0
  double timestamp = 0.0;     ///< seconds (colour stream's clock)
  ImageRGB8 color;            ///< sRGB, colour intrinsics' size; may be empty when color_yuv is given
  /// The colour frame in Y'CbCr instead (the runtime converts it on the GPU; `color` is then not
  /// read and may be empty). Where both are given, color_yuv is the one used.
  std::optional<YuvImage> color_yuv;
  ImageU16 depth;             ///< registered to colour; depth_scale units per metre; 0 = invalid
  double depth_timestamp = 0.0;
  std::optional<Pose> pose;   ///< from groundtruth.txt or tracking; empty when unknown
  std::optional<ImageRGBF> env;  ///< environment image in linear radiance, if the source has one
};

}  // namespace mrgi
