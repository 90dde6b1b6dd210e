// Reading the frame's raw camera uploads (RGB8 colour and u16 depth packed into uint words, as
// the runtime copies them) and the nearest-sample gather from the internal image into either
// camera. Shared by recon/depth_to_positions.comp and ssrt/depth_input.comp, which both start
// from the raw frame. The including shader declares, before including this file:
//   readonly buffer ... { uint color_words[]; };  readonly buffer ... { uint depth_words[]; };
// and includes shared/mrgi_shared.h (project_pinhole).
#ifndef MRGI_UPLOAD_GATHER_GLSL
#define MRGI_UPLOAD_GATHER_GLSL

uint color_byte(uint index) { return (color_words[index >> 2] >> ((index & 3u) * 8u)) & 0xffu; }
uint depth_value(uint index) { return (depth_words[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu; }

// Nearest pixel of a camera with intrinsics k and size for a camera-space ray (any z > 0);
// (-1, -1) outside the image. Never interpolated: between a foreground and a background surface
// an interpolated depth would be a surface that does not exist.
ivec2 nearest_pixel(vec3 ray, vec4 k, ivec2 size) {
  vec2 p = project_pinhole(ray, k);
  ivec2 q = ivec2(floor(p + 0.5));
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return ivec2(-1);
  return q;
}

#endif  // MRGI_UPLOAD_GATHER_GLSL
