// OpenNI2 left out of this build (MRGI_WITH_OPENNI2=OFF): absent.h.
#include "absent/absent.h"
#include "mrgi/platform/openni.h"

namespace mrgi {
namespace {
Error openni_absent() { return platform_absent::absent("OpenNI2", "MRGI_WITH_OPENNI2", "libopenni2-dev"); }
}  // namespace

Status openni_initialize() { return openni_absent(); }
Expected<std::vector<OpenNIDeviceEntry>> list_openni_devices() { return openni_absent(); }
Expected<std::unique_ptr<InputSource>> open_openni_source(const std::string&, const OpenNISettings&) {
  return openni_absent();
}
const OpenNIStreamReport* openni_report(const InputSource&) { return nullptr; }

}  // namespace mrgi
