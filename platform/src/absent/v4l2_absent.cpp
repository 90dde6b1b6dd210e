// V4L2 left out of this build (MRGI_WITH_V4L2=OFF): absent.h. Listing finds no node (the
// adapter list of `mrgi devices` says why).
#include "absent/absent.h"
#include "mrgi/platform/v4l2.h"

namespace mrgi {

std::vector<V4L2NodeEntry> list_v4l2_nodes() { return {}; }
Expected<std::unique_ptr<InputSource>> open_v4l2_source(const std::string&, const CameraSettings&) {
  return platform_absent::absent("V4L2", "MRGI_WITH_V4L2", "libv4l-dev");
}

}  // namespace mrgi
