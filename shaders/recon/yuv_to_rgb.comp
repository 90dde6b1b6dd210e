#version 460
// A Y'CbCr colour frame (mrgi/frame.h YuvImage: NV12 or YUYV, 8-bit, as the camera delivered it)
// into the colour words every pass reads the camera through (common/upload_gather.glsl
// color_words: one a pixel), with shared/mrgi_shared.h yuv_to_rgb8_packed. One invocation per 4
// pixels in row-major order (a YUYV word holds two of them). The chroma is the nearest sample (the pair's for
// YUYV, the 2 x 2 block's for NV12), as the camera's own conversion does it on the host
// (platform/src/common/pixel_convert.cpp).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) readonly uniform uimageBuffer yuv_words;   // the frame's bytes
layout(set = 0, binding = 1, r32ui) writeonly uniform uimageBuffer rgb_words;  // one word a pixel, R | G << 8 | B << 16
struct ConvertConstants {
  ivec4 frame;   // x width, y height (even), z layout (MRGI_YUV_NV12 / _YUYV), w groups a dispatch row
  ivec4 format;  // x matrix (MRGI_YUV_BT601 / _BT709), y 1 = full range
};
layout(push_constant) uniform Convert { ConvertConstants convert; };

uint byte_at(uint offset) { return (imageLoad(yuv_words, int(offset >> 2u)).x >> ((offset & 3u) * 8u)) & 0xffu; }

// The packed RGB of pixel i (row-major), 0 past the frame's end.
uint rgb_of(uint i, uint w, uint h) {
  if (i >= w * h) return 0u;
  uint x = i % w, y = i / w;
  uint luma, cb, cr;
  if (convert.frame.z == MRGI_YUV_YUYV) {
    uint pair = imageLoad(yuv_words, int((y * w + x) >> 1u)).x;  // Y'0 Cb Y'1 Cr
    luma = ((x & 1u) == 0u ? pair : pair >> 16u) & 0xffu;
    cb = (pair >> 8u) & 0xffu;
    cr = (pair >> 24u) & 0xffu;
  } else {
    luma = byte_at(i);
    uint c = w * h + (y >> 1u) * w + (x & ~1u);  // even: Cb and Cr lie in one word
    uint word = imageLoad(yuv_words, int(c >> 2u)).x >> ((c & 3u) * 8u);
    cb = word & 0xffu;
    cr = (word >> 8u) & 0xffu;
  }
  return yuv_to_rgb8_packed(float(luma), float(cb), float(cr), convert.format.x, convert.format.y != 0);
}

void main() {
  const uint w = uint(convert.frame.x), h = uint(convert.frame.y);
  const uint group = gl_GlobalInvocationID.y * uint(convert.frame.w) + gl_GlobalInvocationID.x;
  if (gl_GlobalInvocationID.x >= uint(convert.frame.w) || group * 4u >= w * h) return;
  uint p0 = rgb_of(group * 4u, w, h), p1 = rgb_of(group * 4u + 1u, w, h);
  uint p2 = rgb_of(group * 4u + 2u, w, h), p3 = rgb_of(group * 4u + 3u, w, h);
  imageStore(rgb_words, int(group * 4u), uvec4(p0));
  imageStore(rgb_words, int(group * 4u + 1u), uvec4(p1));
  imageStore(rgb_words, int(group * 4u + 2u), uvec4(p2));
  imageStore(rgb_words, int(group * 4u + 3u), uvec4(p3));
}
