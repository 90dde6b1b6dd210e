#include "mrgi/platform/apriltag.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <Eigen/Dense>
#include <glm/gtc/quaternion.hpp>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagStandard41h12.h>
}

namespace mrgi {

struct AprilTagDetector::Impl {
  apriltag_family_t* family = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;
  apriltag_detector_t* detector = nullptr;
  AprilTagTrackerSettings settings;
  ImageU8 gray;  // reused across frames
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
    if (family) destroy_family(family);
  }
};

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

Mat3 to_eigen(const glm::dquat& q) {
  const glm::dmat3 m = glm::mat3_cast(q);
  Mat3 r;
  for (int c = 0; c < 3; ++c)
    for (int rr = 0; rr < 3; ++rr) r(rr, c) = m[c][rr];
  return r;
}
glm::dquat to_glm(const Mat3& r) {
  glm::dmat3 m;
  for (int c = 0; c < 3; ++c)
    for (int rr = 0; rr < 3; ++rr) m[c][rr] = r(rr, c);
  return glm::normalize(glm::quat_cast(m));
}
Vec3 to_eigen(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

Mat3 rodrigues(const Vec3& w) {
  const double th = w.norm();
  if (th < 1e-12) return Mat3::Identity();
  return Eigen::AngleAxisd(th, w / th).toRotationMatrix();
}

// World-to-camera rigid transform, the unknown of the solve.
struct Extrinsics {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
};

struct Correspondence {
  Vec3 world;
  Eigen::Vector2d pixel;
};

// Reprojection residuals (2 per point); a point behind the camera gets a large constant.
Eigen::VectorXd residuals(const Extrinsics& e, const std::vector<Correspondence>& pts, const Intrinsics& k) {
  Eigen::VectorXd r(2 * pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec3 c = e.R * pts[i].world + e.t;
    if (c.z() < 1e-6) {
      r(2 * i) = r(2 * i + 1) = 1e4;
      continue;
    }
    r(2 * i) = k.fx * c.x() / c.z() + k.cx - pts[i].pixel.x();
    r(2 * i + 1) = k.fy * c.y() / c.z() + k.cy - pts[i].pixel.y();
  }
  return r;
}

// Levenberg-Marquardt on 6 parameters (rotation vector applied on the left, translation).
Extrinsics refine(Extrinsics e, const std::vector<Correspondence>& pts, const Intrinsics& k) {
  double lambda = 1e-3;
  Eigen::VectorXd r = residuals(e, pts, k);
  double cost = r.squaredNorm();
  for (int iter = 0; iter < 30; ++iter) {
    Eigen::MatrixXd J(r.size(), 6);
    for (int p = 0; p < 6; ++p) {
      const double h = p < 3 ? 1e-6 : 1e-6 * std::max(1.0, e.t.norm());
      Extrinsics a = e, b = e;
      if (p < 3) {
        Vec3 w = Vec3::Zero();
        w(p) = h;
        a.R = rodrigues(w) * e.R;
        b.R = rodrigues(-w) * e.R;
      } else {
        a.t(p - 3) += h;
        b.t(p - 3) -= h;
      }
      J.col(p) = (residuals(a, pts, k) - residuals(b, pts, k)) / (2 * h);
    }
    const Eigen::Matrix<double, 6, 6> JtJ = J.transpose() * J;
    const Eigen::Matrix<double, 6, 1> g = J.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      Eigen::Matrix<double, 6, 6> A = JtJ;
      A.diagonal() *= (1.0 + lambda);
      const Eigen::Matrix<double, 6, 1> step = A.ldlt().solve(-g);
      Extrinsics n = e;
      n.R = rodrigues(step.head<3>()) * e.R;
      n.t = e.t + step.tail<3>();
      const Eigen::VectorXd nr = residuals(n, pts, k);
      if (nr.squaredNorm() < cost) {
        e = n, r = nr;
        const double gain = cost - nr.squaredNorm();
        cost = nr.squaredNorm();
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
        if (gain < 1e-12 * (1 + cost)) return e;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return e;
}

struct FamilyEntry {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};
const FamilyEntry kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
};

}  // namespace

AprilTagDetector::AprilTagDetector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AprilTagDetector::AprilTagDetector(AprilTagDetector&&) noexcept = default;
AprilTagDetector& AprilTagDetector::operator=(AprilTagDetector&&) noexcept = default;
AprilTagDetector::~AprilTagDetector() = default;

Expected<AprilTagDetector> AprilTagDetector::create(const std::string& family, const AprilTagTrackerSettings& s) {
  const FamilyEntry* f = nullptr;
  for (const auto& e : kFamilies)
    if (family == e.name) f = &e;
  if (!f) {
    std::string names;
    for (const auto& e : kFamilies) names += (names.empty() ? "" : ", ") + std::string(e.name);
    return fail(ErrorKind::BadInput, "apriltag family '" + family + "' is not supported (supported: " + names + ")");
  }
  if (s.quad_decimate < 1.0 || s.threads < 1 || s.max_hamming < 0 || s.max_hamming > 3)
    return fail(ErrorKind::BadUsage, "apriltag settings: quad_decimate >= 1, threads >= 1, max_hamming 0..3");
  auto impl = std::make_unique<Impl>();
  impl->settings = s;
  impl->family = f->create();
  impl->destroy_family = f->destroy;
  impl->detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(impl->detector, impl->family, s.max_hamming);
  impl->detector->quad_decimate = float(s.quad_decimate);
  impl->detector->quad_sigma = float(s.quad_sigma);
  impl->detector->nthreads = s.threads;
  impl->detector->refine_edges = s.refine_edges;
  return AprilTagDetector(std::move(impl));
}

std::vector<AprilTagDetection> AprilTagDetector::detect(const ImageRGB8& color) {
  ImageU8& g = impl_->gray;
  if (g.width != color.width || g.height != color.height) g = ImageU8(color.width, color.height);
  const uint8_t* s = color.data.data();
  for (size_t i = 0; i < g.data.size(); ++i, s += 3) g.data[i] = uint8_t((77 * s[0] + 150 * s[1] + 29 * s[2] + 128) >> 8);
  return detect_gray(g);
}

std::vector<AprilTagDetection> AprilTagDetector::detect_gray(const ImageU8& gray) {
  std::vector<AprilTagDetection> out;
  if (gray.empty()) return out;
  // libapriltag blurs its input in place when quad_sigma != 0 at decimation 1: work on a copy.
  if (impl_->settings.quad_sigma != 0.0 && &gray != &impl_->gray) {
    impl_->gray = gray;
    return detect_gray(impl_->gray);
  }
  image_u8_t im{gray.width, gray.height, gray.width, const_cast<uint8_t*>(gray.data.data())};
  zarray_t* dets = apriltag_detector_detect(impl_->detector, &im);
  for (int i = 0; i < zarray_size(dets); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(dets, i, &d);
    if (d->hamming > impl_->settings.max_hamming || d->decision_margin < impl_->settings.min_decision_margin) continue;
    AprilTagDetection a;
    a.id = d->id;
    a.hamming = d->hamming;
    a.decision_margin = d->decision_margin;
    for (int c = 0; c < 4; ++c) a.corners[c] = {d->p[c][0], d->p[c][1]};
    a.center = {d->c[0], d->c[1]};
    out.push_back(a);
  }
  apriltag_detections_destroy(dets);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.id != b.id ? a.id < b.id : a.center.x < b.center.x;
  });
  return out;
}

Expected<PoseSolve> solve_camera_pose(const std::vector<AprilTagDetection>& detections, const AprilTagSettings& tags,
                                      const Intrinsics& k, double max_rms_px) {
  const double s = 0.5 * tags.size_m;
  // Corners in the tag frame (x right, y up, z out of the face), libapriltag's order.
  const Vec3 local[4] = {{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}};
  // libapriltag's tag frame is x right, y down, z into the tag: ours is that flipped about x.
  const Mat3 flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  std::vector<Correspondence> pts;
  std::optional<Extrinsics> best;
  double best_err = 0;
  int used = 0;
  for (const auto& det : detections) {
    auto known = std::find_if(tags.tags.begin(), tags.tags.end(), [&](const TagPose& t) { return t.id == det.id; });
    if (known == tags.tags.end()) continue;
    ++used;
    const Mat3 Rtw = to_eigen(known->tag_to_world.rotation);
    const Vec3 ttw = to_eigen(known->tag_to_world.translation);
    for (int c = 0; c < 4; ++c) pts.push_back({Rtw * local[c] + ttw, {det.corners[c].x, det.corners[c].y}});
    // A single-tag estimate from libapriltag seeds the joint solve.
    apriltag_detection_t d{};
    d.id = det.id;
    for (int c = 0; c < 4; ++c) d.p[c][0] = det.corners[c].x, d.p[c][1] = det.corners[c].y;
    d.c[0] = det.center.x, d.c[1] = det.center.y;
    // libapriltag's pose code starts from the detection's homography (tag square -1..1 to
    // pixels); it is recomputed here from the corners by DLT. Debian's libapriltag 3.3 exports
    // only the detector and estimate_tag_pose, so matd_t blocks are made and freed directly:
    // matd_create allocates one calloc block {nrows, ncols, data[]}, which free() releases.
    Eigen::Matrix<double, 8, 8> A;
    Eigen::Matrix<double, 8, 1> b;
    const double src[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
    for (int c = 0; c < 4; ++c) {
      const double x = src[c][0], y = src[c][1], u = det.corners[c].x, v = det.corners[c].y;
      A.row(2 * c) << x, y, 1, 0, 0, 0, -u * x, -u * y;
      A.row(2 * c + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
      b(2 * c) = u;
      b(2 * c + 1) = v;
    }
    const Eigen::Matrix<double, 8, 1> h = A.fullPivLu().solve(b);
    if (!h.allFinite()) continue;
    d.H = static_cast<matd_t*>(std::calloc(1, sizeof(matd_t) + 9 * sizeof(double)));
    d.H->nrows = d.H->ncols = 3;
    for (int i = 0; i < 8; ++i) d.H->data[i] = h(i);
    d.H->data[8] = 1.0;
    apriltag_detection_info_t info{&d, tags.size_m, k.fx, k.fy, k.cx, k.cy};
    apriltag_pose_t pose{};
    const double err = estimate_tag_pose(&info, &pose);
    std::free(d.H);
    if (!pose.R || !pose.t) {
      std::free(pose.R);
      std::free(pose.t);
      continue;
    }
    Mat3 Rlib;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Rlib(r, c) = MATD_EL(pose.R, r, c);
    const Vec3 t(MATD_EL(pose.t, 0, 0), MATD_EL(pose.t, 1, 0), MATD_EL(pose.t, 2, 0));
    std::free(pose.R);
    std::free(pose.t);
    const Mat3 Rtc = Rlib * flip;  // our tag frame -> camera
    // world -> camera = (tag -> camera) * (world -> tag)
    Extrinsics e;
    e.R = Rtc * Rtw.transpose();
    e.t = t - e.R * ttw;
    if (!best || err < best_err) best = e, best_err = err;
  }
  if (used == 0) return fail(ErrorKind::NotFound, "no tag with a known world pose is visible");
  if (!best) return fail(ErrorKind::NotFound, "libapriltag could not estimate a pose from the visible tags");
  const Extrinsics e = refine(*best, pts, k);
  const Eigen::VectorXd r = residuals(e, pts, k);
  const double rms = std::sqrt(r.squaredNorm() / double(pts.size()));
  if (!std::isfinite(rms) || rms > max_rms_px)
    return fail(ErrorKind::BadInput, "camera pose rejected: corner reprojection RMS " + std::to_string(rms) +
                                         " px exceeds " + std::to_string(max_rms_px) + " px (wrong tag size, intrinsics or tag poses?)");
  PoseSolve out;
  const Mat3 Rcw = e.R.transpose();
  out.camera_to_world.rotation = to_glm(Rcw);
  const Vec3 tcw = -Rcw * e.t;
  out.camera_to_world.translation = {tcw.x(), tcw.y(), tcw.z()};
  out.tags_used = used;
  out.rms_px = rms;
  return out;
}

Expected<AprilTagTracker> AprilTagTracker::create(const AprilTagSettings& tags, const Intrinsics& intrinsics,
                                                  const AprilTagTrackerSettings& settings) {
  if (tags.tags.empty()) return fail(ErrorKind::BadInput, "capture.json apriltag.tags: no tag with a world pose is given");
  if (!(tags.size_m > 0.0)) return fail(ErrorKind::BadInput, "capture.json apriltag.size_m must be > 0 (metres)");
  if (settings.smoothing_tau_s < 0.0 || settings.hold_s < 0.0)
    return fail(ErrorKind::BadUsage, "apriltag tracker: smoothing_tau_s and hold_s must be >= 0");
  auto det = AprilTagDetector::create(tags.family, settings);
  if (!det.ok()) return det.error();
  return AprilTagTracker(std::move(det.value()), tags, intrinsics, settings);
}

TrackingResult AprilTagTracker::track(const ImageRGB8& color, double timestamp) {
  TrackingResult res;
  const Intrinsics k = (color.width == intrinsics_.width && color.height == intrinsics_.height)
                           ? intrinsics_
                           : intrinsics_.scaled_to(color.width, color.height);
  const auto dets = detector_.detect(color);
  res.tags_detected = int(dets.size());
  auto solve = solve_camera_pose(dets, tags_, k, settings_.max_rms_px);
  if (solve.ok()) {
    res.raw_pose = solve->camera_to_world;
    res.tags_used = solve->tags_used;
    res.rms_px = solve->rms_px;
    const bool restart = state_ == TrackingState::NotAcquired || state_ == TrackingState::Lost ||
                         settings_.smoothing_tau_s == 0.0 || timestamp <= last_time_;
    if (restart) {
      smoothed_ = solve->camera_to_world;
    } else {
      const double alpha = 1.0 - std::exp(-(timestamp - last_time_) / settings_.smoothing_tau_s);
      smoothed_.translation = glm::mix(smoothed_.translation, solve->camera_to_world.translation, alpha);
      smoothed_.rotation = glm::normalize(glm::slerp(smoothed_.rotation, solve->camera_to_world.rotation, alpha));
    }
    state_ = TrackingState::Tracking;
    last_seen_ = timestamp;
  } else if (state_ == TrackingState::Tracking || state_ == TrackingState::Holding) {
    state_ = (timestamp - last_seen_ <= settings_.hold_s) ? TrackingState::Holding : TrackingState::Lost;
  }
  last_time_ = timestamp;
  res.state = state_;
  if (state_ == TrackingState::Tracking || state_ == TrackingState::Holding) res.pose = smoothed_;
  return res;
}

TrackingResult AprilTagTracker::fill_pose(InputFrame& frame) {
  TrackingResult r = track(frame.color, frame.timestamp);
  frame.pose = r.pose;
  return r;
}

}  // namespace mrgi
