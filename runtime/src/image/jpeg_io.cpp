// JPEG decoding through libjpeg-turbo (texture_decode.h). libjpeg reports errors through
// error_exit, which must not return: it longjmps back here, the decoder is destroyed, and the
// caller gets the library's message.
#include <cstdio>
// jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>

#include <csetjmp>
#include <cstring>
#include <string>

#include "image/texture_decode.h"

namespace mrgi {
namespace {

struct ErrorSink {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_error(j_common_ptr cinfo) {
  auto* sink = reinterpret_cast<ErrorSink*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, sink->message);
  std::longjmp(sink->jump, 1);
}

void on_message(j_common_ptr, int) {}  // warnings (e.g. corrupt data recovered) are not printed

}  // namespace

Expected<ImageRGBA8> decode_jpeg_rgba8(const uint8_t* data, size_t size) {
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8)
    return fail(ErrorKind::BadInput, "not a JPEG (bad signature)");
  if (size > 0x7fffffffu) return fail(ErrorKind::BadInput, "JPEG larger than 2 GiB");
  jpeg_decompress_struct cinfo;
  ErrorSink sink;
  std::memset(&sink, 0, sizeof(sink));
  cinfo.err = jpeg_std_error(&sink.mgr);
  sink.mgr.error_exit = on_error;
  sink.mgr.emit_message = on_message;
  ImageRGBA8 out;
  std::string message;
  if (setjmp(sink.jump)) {
    jpeg_destroy_decompress(&cinfo);
    return fail(ErrorKind::BadInput, std::string("cannot decode JPEG: ") + sink.message);
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
    jpeg_destroy_decompress(&cinfo);
    return fail(ErrorKind::BadInput, "JPEG is CMYK (only grey and colour JPEGs are read)");
  }
  if (uint64_t(cinfo.image_width) * cinfo.image_height > kMaxTexturePixels || cinfo.image_width == 0 ||
      cinfo.image_height == 0) {
    const std::string size_text = std::to_string(cinfo.image_width) + "x" + std::to_string(cinfo.image_height);
    jpeg_destroy_decompress(&cinfo);
    return fail(ErrorKind::BadInput, "JPEG is " + size_text + ", over the limit of " +
                                         std::to_string(kMaxTexturePixels) + " pixels (or empty)");
  }
  cinfo.out_color_space = JCS_EXT_RGBA;  // libjpeg-turbo extension: RGBA with alpha 255
  jpeg_start_decompress(&cinfo);
  out = ImageRGBA8(int(cinfo.output_width), int(cinfo.output_height), 255);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = out.data.data() + size_t(cinfo.output_scanline) * cinfo.output_width * 4;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return out;
}

}  // namespace mrgi
