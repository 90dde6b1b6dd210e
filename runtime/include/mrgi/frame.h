/// \file
/// One input frame, as every source delivers it: capture replay, OpenNI2, V4L2, libcamera.
/// Conventions (docs/DESIGN.md): camera is OpenCV/TUM (x right, y down, looking along +z); poses are
/// camera-to-world; world is right-handed, metres, +y up.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

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

struct InputFrame {
  int64_t index = 0;          ///< frame number in the stream, from 0
  double timestamp = 0.0;     ///< seconds (colour stream's clock)
  ImageRGB8 color;            ///< sRGB, colour intrinsics' size
  ImageU16 depth;             ///< registered to colour; depth_scale units per metre; 0 = invalid
  double depth_timestamp = 0.0;
  std::optional<Pose> pose;   ///< from groundtruth.txt or tracking; empty when unknown
  std::optional<ImageRGBF> env;  ///< environment image in linear radiance, if the source has one
};

}  // namespace mrgi
