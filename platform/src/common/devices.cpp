#include "mrgi/platform/devices.h"

namespace mrgi {

DeviceReport list_devices_all_adapters() {
  DeviceReport r;
  auto openni = list_openni_devices();
  if (openni.ok()) r.openni = std::move(openni.value());
  else r.openni_status = openni.error();
  r.v4l2 = list_v4l2_nodes();
  auto cams = list_libcamera_cameras();
  if (cams.ok()) r.libcamera = std::move(cams.value());
  else r.libcamera_status = cams.error();
  r.usb = scan_usb();
  return r;
}

}  // namespace mrgi
