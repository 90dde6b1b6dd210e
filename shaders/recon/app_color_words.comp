#version 460
// A colour frame given as the app's image (mrgi/vulkan_device.h AppInputImages), after the
// transfer copied its 4-byte texels into the colour words every pass reads the camera through
// (common/upload_gather.glsl color_words: one word a pixel, R | G << 8 | B << 16, the top byte
// ignored). An RGBA image's texels are those words as they are: this pass runs only for what
// the copy cannot do.
//   - BGRA order: the words are swapped to R | G << 8 | B << 16 in place.
//   - Where the composite goes to the app's image at the camera's size, the composite's camera
//     words: the same with alpha 0 (no virtual pixel; compose.comp's camera path writes the
//     same), so the output is the camera frame wherever compose writes nothing, without a
//     camera pass.
// One invocation per 16 pixels (four uvec4 in, four out each); the buffers hold whole groups of
// 16 (recon/reconstruction.cpp, compose/compose.cpp).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) buffer ColorWords { uvec4 color4[]; };     // 4 pixels an element
layout(std430, set = 0, binding = 1) writeonly buffer CameraWords { uvec4 camera4[]; };  // RGBA8, alpha 0
struct WordsConstants {
  ivec4 frame;  // x pixels, y unused, z 1 = BGRA order (swap in place), w 1 = write the camera words
};
layout(push_constant) uniform Words { WordsConstants words_block; };
WordsConstants words;  // private copy (MRGI_UNIFORM_COPIES, common/frame_constants.glsl): read
                       // after a branch, a push constant is gathered lane by lane on lavapipe

uvec4 rgb_of(uvec4 t) {
  return words.frame.z != 0 ? ((t >> 16u) & 0xffu) | (t & 0xff00u) | ((t & 0xffu) << 16u) : t & 0xffffffu;
}

void main() {
  words = words_block;
  const uint n = uint(words.frame.x);
  const uint q = gl_WorkGroupID.x * 64u + gl_LocalInvocationID.x;  // 16 pixels: elements 4q..4q+3
  if (q * 16u >= n) return;
  for (uint k = 0u; k < 4u; ++k) {
    const uvec4 c = rgb_of(color4[4u * q + k]);
    if (words.frame.z != 0) color4[4u * q + k] = c;
    if (words.frame.w != 0) camera4[4u * q + k] = c;
  }
}
