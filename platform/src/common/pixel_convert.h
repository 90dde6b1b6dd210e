// Camera pixel formats (V4L2 and libcamera deliver the same few) and their conversion to the
// runtime's sRGB colour frame. YUV is BT.601 limited range, what UVC webcams send. MJPEG is
// decoded with stb_image; UVC cameras often omit the Huffman tables (the MJPEG convention), so
// the standard tables of JPEG Annex K.3 are inserted when a frame has none.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi {

enum class PixelFormat { YUYV, UYVY, RGB24, BGR24, NV12, MJPEG };

const char* to_string(PixelFormat f);
// V4L2 fourcc ('YUYV', 'RGB3', ...) to a format mrgi converts; nullopt when unsupported.
std::optional<PixelFormat> pixel_format_from_v4l2(uint32_t fourcc);
uint32_t v4l2_fourcc_of(PixelFormat f);
// libcamera's format names ("YUYV", "RGB888", "BGR888", "NV12", "MJPEG"); nullopt when unsupported.
std::optional<PixelFormat> pixel_format_from_libcamera(const std::string& name);
std::string fourcc_text(uint32_t fourcc);  // 'YUYV' -> "YUYV", for messages

// One filled buffer as a device hands it over (a view: nothing is owned).
struct RawFrame {
  PixelFormat format = PixelFormat::YUYV;
  int width = 0, height = 0;
  int stride = 0;              // bytes per row of the first plane (0 = tightly packed)
  const uint8_t* data = nullptr;
  size_t size = 0;             // bytes used in the buffer
  double timestamp = 0.0;      // seconds, the device's clock
  uint64_t sequence = 0;       // the driver's frame counter
};

// A YUYV or NV12 frame into `out` as it is (rows packed tightly, the stride dropped), BT.601
// limited range: for the runtime to convert on the GPU (CameraSettings::yuv_to_runtime).
// BadInput as convert_to_rgb8 for a short buffer, an odd size or another format.
Status copy_yuv(const RawFrame& frame, YuvImage& out);

// Converts into `out`, which is resized only when the frame size changes. Errors (BadInput) name
// the format, the size and what is wrong (short buffer, corrupt JPEG, size mismatch).
Status convert_to_rgb8(const RawFrame& frame, ImageRGB8& out);

// MJPEG helper, exposed for tests: the frame with the Annex K.3 Huffman tables inserted before
// the first SOS marker when it has no DHT segment; unchanged otherwise.
std::vector<uint8_t> mjpeg_with_huffman_tables(const uint8_t* jpeg, size_t size);

// Encoders used by tests and by recorded-buffer backends (inverse of the conversions above).
std::vector<uint8_t> encode_yuyv(const ImageRGB8& rgb);
std::vector<uint8_t> encode_nv12(const ImageRGB8& rgb);

}  // namespace mrgi
