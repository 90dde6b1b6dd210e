/// \file
/// OpenNI2 input (Debian's libopenni2): live devices (PrimeSense/Asus Xtion through the PS1080
/// driver, others through whatever drivers OpenNI2 finds) and .oni file playback.
///
/// Driver discovery: libOpenNI2 reads /etc/openni2/OpenNI.ini (Debian's build) and loads the drivers
/// from "OpenNI2/Drivers" relative to its own shared library, i.e.
/// `/usr/lib/<triplet>/OpenNI2/Drivers` (libOniFile.so plays .oni files). Neither depends on the
/// working directory, so playback works from anywhere.
///
/// Frames: one InputFrame pairs the next colour frame with the next depth frame (OpenNI2 delivers
/// them on separate streams; the file driver interleaves them). Timestamps are the device's
/// microsecond clocks, in seconds. Depth is kept in the sensor's units: 1 mm -> depth_scale 1000,
/// 100 um -> 10000. Mirrored streams (OpenNI 1.x recordings default to mirroring) are flipped back
/// so x grows to the camera's right, as the pinhole model assumes.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/platform/source.h"

namespace mrgi {

struct OpenNISettings {
  /// Live devices: requested mode for both streams (the closest supported mode is taken).
  int width = 640;
  int height = 480;
  int fps = 30;
  /// Live devices: ask the device to register depth to colour (IMAGE_REGISTRATION_DEPTH_TO_COLOR)
  /// when it supports it.
  bool register_depth_to_color = true;
  /// Playback: the longest a file may go without delivering its next frame before it is called
  /// corrupt (ms). The file driver runs as fast as possible, so a healthy file never comes close.
  int playback_stall_ms = 2000;
};

/// What OpenNI2 reports about registration and field of view, kept with the source for reports.
struct OpenNIStreamReport {
  bool is_file = false;
  bool registered = false;          ///< depth is in the colour camera's geometry
  std::string registration_source;  ///< where `registered` was read from
  std::string color_fov_source;     ///< "colour stream" or why another was used
  int depth_frames_in_file = -1;    ///< playback only
  int color_frames_in_file = -1;
  bool mirrored = false;            ///< frames were mirrored and are flipped back
};

struct OpenNIDeviceEntry {
  std::string uri;
  std::string name;
  std::string vendor;
  int usb_vendor_id = 0;
  int usb_product_id = 0;
};

/// Initialises OpenNI2 once per process; the error names the drivers folder it looked in.
MRGI_API Status openni_initialize();

/// Devices OpenNI2's drivers enumerate now (may be empty).
MRGI_API Expected<std::vector<OpenNIDeviceEntry>> list_openni_devices();

/// URI: empty = the first device OpenNI2 finds; a path ending in .oni = playback; otherwise a
/// device URI as list_openni_devices() gives. Errors: NotFound (no device, missing file),
/// BadInput (corrupt or truncated file), Device (driver refused).
MRGI_API Expected<std::unique_ptr<InputSource>> open_openni_source(const std::string& uri,
                                                          const OpenNISettings& settings = {});

/// The report of a source made by open_openni_source (nullptr for other sources).
MRGI_API const OpenNIStreamReport* openni_report(const InputSource& source);

}  // namespace mrgi
