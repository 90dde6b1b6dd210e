// The tracking states' names: the same with or without the AprilTag adapter in the build.
#include "mrgi/platform/apriltag.h"

namespace mrgi {

const char* to_string(TrackingState s) {
  switch (s) {
    case TrackingState::NotAcquired: return "not-acquired";
    case TrackingState::Tracking: return "tracking";
    case TrackingState::Holding: return "holding";
    case TrackingState::Lost: return "lost";
  }
  return "?";
}

}  // namespace mrgi
