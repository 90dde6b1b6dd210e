/// \file
/// AprilTag camera tracking (Debian's libapriltag 3.3): detect tags in the colour frame, solve the
/// camera pose from the tag size, the intrinsics and the known tag-to-world poses (capture.json
/// "apriltag"), smooth it over time, and say explicitly when tracking is lost. Used when a capture
/// has no groundtruth.txt.
///
/// Tag frame (what TagPose::tag_to_world maps to the world): origin at the centre of the tag's
/// black square, x to the right and y up as the tag is printed (read upright), z out of the
/// printed face towards a viewer. A tag lying face-up on a +y-up floor, read from the -z side, is
/// tag_to_world = rotation of -90 deg about x.
///
/// Pose solution: every detected tag with a known pose gives a first estimate (libapriltag's
/// estimate_tag_pose, orthogonal iteration); the best is refined by Gauss-Newton on the
/// reprojection error of all corners of all known tags at once, so several tags constrain one
/// camera pose. A solve whose RMS reprojection error exceeds max_rms_px is rejected.
///
/// Smoothing: an exponential filter with time constant tau = smoothing_tau_s: at a frame dt
/// seconds after the last, position moves by alpha = 1 - exp(-dt / tau) towards the new estimate
/// (lerp), orientation likewise (slerp). tau = 0 disables it. After a loss the filter restarts.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/platform/capture.h"

namespace mrgi {

struct AprilTagDetection {
  int id = 0;
  int hamming = 0;                       ///< corrected bit errors
  double decision_margin = 0.0;
  /// Corners in pixels (pixel centres at integer coordinates), libapriltag's order: in the tag
  /// frame above, (-s,-s), (s,-s), (s,s), (-s,s) with s = half the black square's edge, i.e.
  /// bottom-left, bottom-right, top-right, top-left of the upright tag.
  std::array<glm::dvec2, 4> corners{};
  glm::dvec2 center{0.0};
};

struct AprilTagTrackerSettings {
  double quad_decimate = 2.0;        ///< detector input decimation (speed vs. small-tag recall)
  double quad_sigma = 0.0;           ///< Gaussian blur before quad detection, pixels
  int threads = 1;                   ///< detector threads
  bool refine_edges = true;
  int max_hamming = 1;               ///< reject detections with more corrected bit errors
  double min_decision_margin = 15.0; ///< reject weak decodes (false positives in texture)
  double max_rms_px = 3.0;           ///< reject a pose whose corners reproject worse (pixels RMS)
  double smoothing_tau_s = 0.1;      ///< time constant of the exponential filter, seconds
  double hold_s = 0.5;               ///< keep the last pose this long without tags, then Lost
};

enum class TrackingState {
  NotAcquired,  ///< no pose yet
  Tracking,     ///< pose from this frame's tags
  Holding,      ///< no usable tag this frame; last pose kept (younger than hold_s)
  Lost,         ///< no usable tag for longer than hold_s: no pose
};
MRGI_API const char* to_string(TrackingState s);

struct TrackingResult {
  TrackingState state = TrackingState::NotAcquired;
  std::optional<Pose> pose;      ///< smoothed camera-to-world; empty when NotAcquired or Lost
  std::optional<Pose> raw_pose;  ///< this frame's solve, unsmoothed
  int tags_detected = 0;         ///< all decoded tags of the family
  int tags_used = 0;             ///< those with a known world pose
  double rms_px = 0.0;           ///< reprojection RMS of the raw pose
};

class MRGI_API AprilTagDetector {
 public:
  static Expected<AprilTagDetector> create(const std::string& family, const AprilTagTrackerSettings& settings = {});
  AprilTagDetector(AprilTagDetector&&) noexcept;
  AprilTagDetector& operator=(AprilTagDetector&&) noexcept;
  ~AprilTagDetector();
  /// Grey is converted from sRGB colour with the detector's luma weights. Sorted by id, then x.
  std::vector<AprilTagDetection> detect(const ImageRGB8& color);
  std::vector<AprilTagDetection> detect_gray(const ImageU8& gray);

 private:
  struct Impl;
  explicit AprilTagDetector(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Camera-to-world pose from detections of tags with known poses (nullopt with a reason when no
/// known tag is seen or the solve is rejected). Exposed for tests.
struct PoseSolve {
  Pose camera_to_world;
  int tags_used = 0;
  double rms_px = 0.0;
};
MRGI_API Expected<PoseSolve> solve_camera_pose(const std::vector<AprilTagDetection>& detections,
                                      const AprilTagSettings& tags, const Intrinsics& intrinsics,
                                      double max_rms_px);

class MRGI_API AprilTagTracker {
 public:
  /// BadInput when the settings have no tags, a non-positive size, or an unknown family.
  static Expected<AprilTagTracker> create(const AprilTagSettings& tags, const Intrinsics& intrinsics,
                                          const AprilTagTrackerSettings& settings = {});
  TrackingResult track(const ImageRGB8& color, double timestamp);
  /// Tracks frame.color and sets frame.pose (left empty when NotAcquired or Lost).
  TrackingResult fill_pose(InputFrame& frame);
  TrackingState state() const { return state_; }

 private:
  AprilTagTracker(AprilTagDetector detector, AprilTagSettings tags, Intrinsics k, AprilTagTrackerSettings s)
      : detector_(std::move(detector)), tags_(std::move(tags)), intrinsics_(k), settings_(s) {}
  AprilTagDetector detector_;
  AprilTagSettings tags_;
  Intrinsics intrinsics_;
  AprilTagTrackerSettings settings_;
  TrackingState state_ = TrackingState::NotAcquired;
  Pose smoothed_;
  double last_seen_ = 0.0, last_time_ = 0.0;
};

}  // namespace mrgi
