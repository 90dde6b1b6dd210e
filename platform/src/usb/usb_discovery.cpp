#include <libusb.h>

#include "mrgi/platform/usb.h"

namespace mrgi {

UsbScan scan_usb() {
  UsbScan scan;
  libusb_context* ctx = nullptr;
  const int r = libusb_init(&ctx);
  if (r != 0) {
    scan.status = std::string("libusb_init failed: ") + libusb_strerror(r) + " (no USB bus visible)";
    return scan;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  if (n < 0) {
    scan.status = std::string("libusb_get_device_list failed: ") + libusb_strerror(int(n));
    libusb_exit(ctx);
    return scan;
  }
  scan.available = true;
  scan.status = n == 0 ? "no USB devices visible" : "ok";
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
    UsbDeviceEntry e;
    e.vendor = d.idVendor;
    e.product = d.idProduct;
    e.bus = libusb_get_bus_number(list[i]);
    e.address = libusb_get_device_address(list[i]);
    e.known = match_usb_sensor(d.idVendor, d.idProduct);
    // Reading the product string needs the device opened, which needs permission: best effort.
    libusb_device_handle* h = nullptr;
    if (d.iProduct && libusb_open(list[i], &h) == 0) {
      unsigned char buf[256];
      const int len = libusb_get_string_descriptor_ascii(h, d.iProduct, buf, sizeof buf);
      if (len > 0) e.product_name.assign(reinterpret_cast<char*>(buf), size_t(len));
      libusb_close(h);
    }
    scan.devices.push_back(e);
  }
  libusb_free_device_list(list, 1);
  libusb_exit(ctx);
  return scan;
}

}  // namespace mrgi
