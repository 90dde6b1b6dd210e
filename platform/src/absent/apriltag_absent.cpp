// AprilTag tracking left out of this build (MRGI_WITH_APRILTAG=OFF): absent.h. No detector or
// tracker can be made, so their other members are never reached; they are defined for the link
// and answer as a tracker that never acquired a pose would.
#include <algorithm>

#include "absent/absent.h"
#include "mrgi/platform/apriltag.h"

namespace mrgi {
namespace {
Error apriltag_absent() { return platform_absent::absent("AprilTag", "MRGI_WITH_APRILTAG", "libapriltag-dev"); }
}  // namespace

struct AprilTagDetector::Impl {};

AprilTagDetector::AprilTagDetector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AprilTagDetector::AprilTagDetector(AprilTagDetector&&) noexcept = default;
AprilTagDetector& AprilTagDetector::operator=(AprilTagDetector&&) noexcept = default;
AprilTagDetector::~AprilTagDetector() = default;
Expected<AprilTagDetector> AprilTagDetector::create(const std::string&, const AprilTagTrackerSettings&) {
  return apriltag_absent();
}
std::vector<AprilTagDetection> AprilTagDetector::detect(const ImageRGB8&) { return {}; }
std::vector<AprilTagDetection> AprilTagDetector::detect_gray(const ImageU8&) { return {}; }

Expected<PoseSolve> solve_camera_pose(const std::vector<AprilTagDetection>&, const AprilTagSettings&,
                                      const Intrinsics&, double) {
  return apriltag_absent();
}

Expected<AprilTagTracker> AprilTagTracker::create(const AprilTagSettings&, const Intrinsics&,
                                                  const AprilTagTrackerSettings&) {
  return apriltag_absent();
}
TrackingResult AprilTagTracker::track(const ImageRGB8&, double timestamp) {
  last_time_ = timestamp;  // as the real tracker keeps it; nothing is ever seen
  last_seen_ = std::min(last_seen_, timestamp);
  return TrackingResult{};
}
TrackingResult AprilTagTracker::fill_pose(InputFrame& frame) {
  frame.pose.reset();
  return TrackingResult{};
}

}  // namespace mrgi
