// The stand-ins of a build without the optional input adapters (platform/src/absent/), linked on
// their own here (the tested build has every adapter): every entry point fails with NotFound
// naming the adapter's CMake option and Debian package; nothing crashes or pretends.
#include <gtest/gtest.h>

#include "mrgi/platform/apriltag.h"
#include "mrgi/platform/libcamera.h"
#include "mrgi/platform/openni.h"
#include "mrgi/platform/usb.h"
#include "mrgi/platform/v4l2.h"

namespace {
using namespace mrgi;

void expect_absent(const Error& e, const char* option, const char* package) {
  EXPECT_EQ(e.kind, ErrorKind::NotFound);
  EXPECT_NE(e.message.find(option), std::string::npos) << e.message;
  EXPECT_NE(e.message.find(package), std::string::npos) << e.message;
}

TEST(AbsentAdapters, EveryEntryPointNamesTheOptionAndThePackage) {
  expect_absent(openni_initialize().error(), "MRGI_WITH_OPENNI2", "libopenni2-dev");
  expect_absent(list_openni_devices().error(), "MRGI_WITH_OPENNI2", "libopenni2-dev");
  expect_absent(open_openni_source("").error(), "MRGI_WITH_OPENNI2", "libopenni2-dev");
  EXPECT_TRUE(list_v4l2_nodes().empty());
  expect_absent(open_v4l2_source("/dev/video0").error(), "MRGI_WITH_V4L2", "libv4l-dev");
  expect_absent(list_libcamera_cameras().error(), "MRGI_WITH_LIBCAMERA", "libcamera-dev");
  expect_absent(open_libcamera_source("").error(), "MRGI_WITH_LIBCAMERA", "libcamera-dev");
  const UsbScan scan = scan_usb();
  EXPECT_FALSE(scan.available);
  EXPECT_NE(scan.status.find("MRGI_WITH_LIBUSB"), std::string::npos) << scan.status;
  EXPECT_NE(match_usb_sensor(0x1d27, 0x0601), nullptr);  // the table of known sensors stays
  expect_absent(AprilTagDetector::create("tag36h11").error(), "MRGI_WITH_APRILTAG", "libapriltag-dev");
  AprilTagSettings tags;
  expect_absent(AprilTagTracker::create(tags, Intrinsics{}).error(), "MRGI_WITH_APRILTAG", "libapriltag-dev");
  expect_absent(solve_camera_pose({}, tags, Intrinsics{}, 3.0).error(), "MRGI_WITH_APRILTAG", "libapriltag-dev");
  EXPECT_STREQ(to_string(TrackingState::Lost), "lost");
}

}  // namespace
