#version 460
// A colour frame given as the app's image (mrgi/vulkan_device.h AppInputImages), copied by a
// transfer into 4-byte words, into the RGB8 words every pass reads the camera through
// (common/upload_gather.glsl color_words). One invocation per 16 pixels in row-major order: four
// 16-byte texels in, exactly 12 words (48 bytes, three uvec4) out, so no two invocations share a
// word and the words are written whole, without atomics; the buffers hold whole groups of 16
// (recon/reconstruction.cpp, compose/compose.cpp). Where the composite goes to the app's image at
// the camera's size, the same invocation also writes its pixels as the composite's camera words
// (R | G << 8 | B << 16, alpha 0: no virtual pixel; compose.comp's camera path writes the same):
// the output is then the camera frame wherever compose writes nothing, without a camera pass.
// Why this shape (lavapipe, 640x480, profiled CPU ms): a texel buffer in (read with vector
// inserts; a storage buffer is read lane by lane, common/upload_gather.glsl) and whole uvec4s
// out: 0.6-0.8 against 1.1-1.6 for 4 pixels an invocation with one word a store.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimageBuffer rgba_words;  // the image, 4 pixels a texel
layout(std430, set = 0, binding = 1) writeonly buffer RgbWords { uvec4 rgb4[]; };  // RGB8, 3 bytes a pixel: 16 pixels in 3
layout(std430, set = 0, binding = 2) writeonly buffer CameraWords { uvec4 camera4[]; };  // RGBA8, alpha 0: 4 pixels in 1
struct PackConstants {
  ivec4 frame;    // x pixels, y unused, z 1 = BGRA order, w 1 = write the camera words
};
layout(push_constant) uniform Pack { PackConstants pack; };

// The packed RGB (R | G << 8 | B << 16) of a texel.
uint rgb_of(uint t) {
  return pack.frame.z != 0 ? ((t >> 16u) & 0xffu) | (t & 0xff00u) | ((t & 0xffu) << 16u) : t & 0xffffffu;
}

void main() {
  const uint n = uint(pack.frame.x);
  const uint q = gl_WorkGroupID.x * 64u + gl_LocalInvocationID.x;  // 16 pixels: texels 4q..4q+3
  if (q * 16u >= n) return;
  uint p[16];
  for (uint k = 0u; k < 4u; ++k) {
    const uvec4 t = imageLoad(rgba_words, int(4u * q + k));
    p[4u * k] = rgb_of(t.x);
    p[4u * k + 1u] = rgb_of(t.y);
    p[4u * k + 2u] = rgb_of(t.z);
    p[4u * k + 3u] = rgb_of(t.w);
    if (pack.frame.w != 0) camera4[4u * q + k] = uvec4(p[4u * k], p[4u * k + 1u], p[4u * k + 2u], p[4u * k + 3u]);
  }
  uint w[12];
  for (uint k = 0u; k < 4u; ++k) {  // bytes r0 g0 b0 r1 | g1 b1 r2 g2 | b2 r3 g3 b3 of each 4
    const uint a = p[4u * k], b = p[4u * k + 1u], c = p[4u * k + 2u], d = p[4u * k + 3u];
    w[3u * k] = a | (b << 24u);
    w[3u * k + 1u] = (b >> 8u) | (c << 16u);
    w[3u * k + 2u] = (c >> 16u) | (d << 8u);
  }
  rgb4[3u * q] = uvec4(w[0], w[1], w[2], w[3]);
  rgb4[3u * q + 1u] = uvec4(w[4], w[5], w[6], w[7]);
  rgb4[3u * q + 2u] = uvec4(w[8], w[9], w[10], w[11]);
}
