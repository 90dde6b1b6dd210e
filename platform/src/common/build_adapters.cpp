#include "mrgi/platform/devices.h"

namespace mrgi {

// MRGI_HAVE_<ADAPTER>: compile definitions of mrgi_platform (platform/CMakeLists.txt), 1 when
// the adapter is in this build.
const std::vector<BuildAdapter>& build_adapters() {
  static const std::vector<BuildAdapter> list = {
      {"openni2", MRGI_HAVE_OPENNI2 != 0, "MRGI_WITH_OPENNI2", "libopenni2-dev"},
      {"v4l2", MRGI_HAVE_V4L2 != 0, "MRGI_WITH_V4L2", "libv4l-dev"},
      {"libcamera", MRGI_HAVE_LIBCAMERA != 0, "MRGI_WITH_LIBCAMERA", "libcamera-dev"},
      {"usb", MRGI_HAVE_LIBUSB != 0, "MRGI_WITH_LIBUSB", "libusb-1.0-0-dev"},
      {"apriltag", MRGI_HAVE_APRILTAG != 0, "MRGI_WITH_APRILTAG", "libapriltag-dev"},
  };
  return list;
}

}  // namespace mrgi
