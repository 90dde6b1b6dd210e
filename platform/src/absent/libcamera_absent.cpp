// libcamera left out of this build (MRGI_WITH_LIBCAMERA=OFF): absent.h.
#include "absent/absent.h"
#include "mrgi/platform/libcamera.h"

namespace mrgi {
namespace {
Error libcamera_absent() { return platform_absent::absent("libcamera", "MRGI_WITH_LIBCAMERA", "libcamera-dev"); }
}  // namespace

Expected<std::vector<LibcameraEntry>> list_libcamera_cameras() { return libcamera_absent(); }
Expected<std::unique_ptr<InputSource>> open_libcamera_source(const std::string&, const CameraSettings&) {
  return libcamera_absent();
}

}  // namespace mrgi
