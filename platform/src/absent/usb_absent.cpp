// USB discovery left out of this build (MRGI_WITH_LIBUSB=OFF): absent.h. The table of known
// sensors (usb/usb_sensors.cpp) stays; the scan is empty and says why.
#include "absent/absent.h"
#include "mrgi/platform/usb.h"

namespace mrgi {

UsbScan scan_usb() {
  UsbScan scan;
  scan.status = platform_absent::absent("USB discovery", "MRGI_WITH_LIBUSB", "libusb-1.0-0-dev").message;
  return scan;
}

}  // namespace mrgi
