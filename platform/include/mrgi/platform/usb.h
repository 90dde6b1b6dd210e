/// \file
/// USB discovery (libusb-1.0): lists the USB devices and recognises depth sensors and cameras by
/// vendor:product id, saying which mrgi adapter serves each.
///
/// Where the ids come from:
///  - Microsoft Kinect v1 (045e:02ae camera, 02ad audio, 02b0 motor; 02bf/02be/02c2 Kinect for
///    Windows) and PrimeSense/Asus (1d27:0600 Xtion/Carmine, 0601 Xtion Pro Live, 0609, ...):
///    Debian's OpenNI2 udev rules, /lib/udev/rules.d/60-libopenni2-0.rules (package libopenni2-0),
///    which list exactly the sensors its drivers open.
///  - Intel RealSense (8086:0a80 R200, 0aa5 SR300, 0ad1 D400, 0ad2 D410, 0ad3 D415, 0ad6 D400 on
///    USB2, 0b07 D435, 0b3a D435i, 0b5c D455, 0b64 L515): the product-id constants of Intel's
///    librealsense (src/ds/d400/d400-private.h and its predecessors). They are UVC devices: colour
///    (and raw Z16 depth nodes mrgi does not convert) appear as V4L2 nodes.
///  - Orbbec (vendor 2bc5, every product): Orbbec's OpenNI2 SDK udev rules. Debian's OpenNI2 has
///    no Orbbec driver, so their UVC colour node is what mrgi can open (V4L2).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/export.h"

namespace mrgi {

struct KnownUsbSensor {
  uint16_t vendor = 0;
  std::optional<uint16_t> product;  ///< nullopt = every product of the vendor
  const char* name = "";
  const char* adapter = "";         ///< "openni", "v4l2", "none"
  const char* note = "";            ///< what the adapter needs, in words
};

/// The table above, in lookup order (a specific product before a vendor-wide entry).
MRGI_API const std::vector<KnownUsbSensor>& known_usb_sensors();
MRGI_API const KnownUsbSensor* match_usb_sensor(uint16_t vendor, uint16_t product);

struct UsbDeviceEntry {
  uint16_t vendor = 0, product = 0;
  int bus = 0, address = 0;
  std::string product_name;              ///< string descriptor when readable (needs device access)
  const KnownUsbSensor* known = nullptr; ///< nullptr: not a sensor mrgi knows
};

struct UsbScan {
  bool available = false;                ///< libusb could open a context (a USB bus is visible)
  std::string status;                    ///< why not, when not
  std::vector<UsbDeviceEntry> devices;   ///< every device seen
};

/// Never fails: no USB bus access (containers, CI) is an empty scan with the reason in `status`.
MRGI_API UsbScan scan_usb();

}  // namespace mrgi
