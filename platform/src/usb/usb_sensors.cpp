// The USB sensors mrgi knows and the adapter that serves each (no libusb needed: the table is
// data; usb_discovery.cpp scans the bus with libusb).
#include "mrgi/platform/usb.h"

namespace mrgi {

const std::vector<KnownUsbSensor>& known_usb_sensors() {
  static const std::vector<KnownUsbSensor> table = {
      {0x045e, 0x02ae, "Microsoft Kinect v1 (camera)", "v4l2",
       "colour via the kernel's gspca_kinect V4L2 driver; OpenNI2 depth needs libfreenect's OpenNI2 driver (not in Debian's libopenni2)"},
      {0x045e, 0x02bf, "Microsoft Kinect for Windows (camera)", "v4l2",
       "colour via gspca_kinect; OpenNI2 depth needs libfreenect's OpenNI2 driver"},
      {0x045e, 0x02be, "Microsoft Kinect for Windows (camera)", "v4l2", "colour via gspca_kinect"},
      {0x045e, 0x02c2, "Microsoft Kinect for Windows (camera)", "v4l2", "colour via gspca_kinect"},
      {0x045e, 0x02ad, "Microsoft Kinect v1 (audio)", "none", "audio part of a Kinect"},
      {0x045e, 0x02b0, "Microsoft Kinect v1 (motor)", "none", "motor part of a Kinect"},
      {0x1d27, 0x0600, "PrimeSense Carmine / Asus Xtion", "openni", "OpenNI2 PS1080 driver: colour + registered depth"},
      {0x1d27, 0x0601, "Asus Xtion Pro Live / Xtion 2", "openni", "OpenNI2 PS1080 driver: colour + registered depth"},
      {0x1d27, 0x0609, "PrimeSense Carmine 1.09", "openni", "OpenNI2 PS1080 driver"},
      {0x1d27, std::nullopt, "PrimeSense sensor", "openni", "OpenNI2 PS1080/PSLink drivers"},
      {0x8086, 0x0a80, "Intel RealSense R200", "v4l2", "UVC colour node"},
      {0x8086, 0x0aa5, "Intel RealSense SR300", "v4l2", "UVC colour node"},
      {0x8086, 0x0ad1, "Intel RealSense D400 (RS400)", "v4l2", "UVC nodes (depth Z16 nodes are not converted)"},
      {0x8086, 0x0ad2, "Intel RealSense D410", "v4l2", "UVC nodes (depth Z16 nodes are not converted)"},
      {0x8086, 0x0ad3, "Intel RealSense D415", "v4l2", "UVC colour node (depth Z16 nodes are not converted)"},
      {0x8086, 0x0ad6, "Intel RealSense D400 on USB2", "v4l2", "UVC nodes"},
      {0x8086, 0x0b07, "Intel RealSense D435", "v4l2", "UVC colour node (depth Z16 nodes are not converted)"},
      {0x8086, 0x0b3a, "Intel RealSense D435i", "v4l2", "UVC colour node (depth Z16 nodes are not converted)"},
      {0x8086, 0x0b5c, "Intel RealSense D455", "v4l2", "UVC colour node (depth Z16 nodes are not converted)"},
      {0x8086, 0x0b64, "Intel RealSense L515", "v4l2", "UVC colour node"},
      {0x2bc5, std::nullopt, "Orbbec depth camera", "v4l2",
       "UVC colour node; depth needs Orbbec's OpenNI2 driver (not in Debian)"},
  };
  return table;
}

const KnownUsbSensor* match_usb_sensor(uint16_t vendor, uint16_t product) {
  for (const auto& k : known_usb_sensors())
    if (k.vendor == vendor && (!k.product || *k.product == product)) return &k;
  return nullptr;
}

}  // namespace mrgi
