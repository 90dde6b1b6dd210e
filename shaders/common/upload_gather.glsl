// Reading the frame's raw camera uploads (colour as one word a pixel, R | G << 8 | B << 16 with
// the top byte ignored, and u16 depth packed two to a word, as the runtime copies them) and the nearest-sample gather from the internal image into either
// camera. Shared by recon/depth_to_positions.comp and the ssrt passes, which start from the raw
// frame. The including shader declares, before including this file:
//   layout(..., r32ui) readonly uniform uimageBuffer color_words;  (and depth_words)
// Storage texel buffers over the upload buffers (gpu::BufferDesc::texel_format), not storage
// buffers: lavapipe reads a storage buffer at per-lane indices lane by lane in a loop with a
// branch per lane, a texel buffer with vector inserts (ssrt's shade, occluders and fuse took
// 10-25 % less).
// and includes shared/mrgi_shared.h (project_pinhole); camera_at() also needs the frame
// constants as `frame` (common/frame_constants.glsl). A shader that reads only the colour
// (compose.comp) defines MRGI_UPLOAD_COLOR_ONLY first and declares no depth_words.
#ifndef MRGI_UPLOAD_GATHER_GLSL
#define MRGI_UPLOAD_GATHER_GLSL

// The sRGB bytes of colour pixel `pixel` (row-major): one word a pixel, so one read (every
// buffer read is a per-lane gather on lavapipe; three bytes a pixel took two), and a frame given
// as the app's RGBA image is its texels as they are (recon/camera_from_app_images.cpp).
uvec3 color_rgb8(uint pixel) {
  uint v = imageLoad(color_words, int(pixel)).x;
  return uvec3(v & 0xffu, (v >> 8u) & 0xffu, (v >> 16u) & 0xffu);
}
#ifdef MRGI_FRAME_CONSTANTS_GLSL
// The radiance the camera measured at colour pixel cp (inside the colour image): its sRGB value
// decoded and divided by the exposure, not clamped (camera_at clamps it to a reflectance).
vec3 camera_radiance(ivec2 cp) {
  vec3 encoded = vec3(color_rgb8(uint(cp.y * frame.color_depth_size.x + cp.x))) / 255.0f;
  return camera_to_radiance(encoded, frame.camera.y);
}
#endif
#ifndef MRGI_UPLOAD_COLOR_ONLY
uint depth_value(uint index) { return (imageLoad(depth_words, int(index >> 1)).x >> ((index & 1u) * 16u)) & 0xffffu; }

// Nearest pixel of a camera with intrinsics k and size for a camera-space ray (any z > 0);
// (-1, -1) outside the image. Never interpolated: between a foreground and a background surface
// an interpolated depth would be a surface that does not exist.
ivec2 nearest_pixel(vec3 ray, vec4 k, ivec2 size) {
  vec2 p = project_pinhole(ray, k);
  ivec2 q = ivec2(floor(p + 0.5));
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return ivec2(-1);
  return q;
}

#ifdef MRGI_FRAME_CONSTANTS_GLSL
// The camera's colour seen through internal pixel position p as linear reflectance, the value
// recon/depth_to_positions.comp writes to real_albedo (sRGB-decoded, divided by the exposure,
// clamped to [0, 1]; the DIR approximation explained there), in rgb; a = 1 where the depth
// camera measured the same ray (its nearest sample is non-zero), else 0. For passes that need
// the camera colour only at some pixels (ssrt: cell centres, shaded tiles) instead of a full
// real G-buffer.
vec4 camera_at(vec2 p) {
  vec3 ray = unproject_pinhole(p, 1.0f, frame.internal_k);
  ivec2 cp = nearest_pixel(ray, frame.color_k, frame.color_depth_size.xy);
  ivec2 dp = nearest_pixel(ray, frame.depth_k, frame.color_depth_size.zw);
  vec3 albedo = cp.x >= 0 ? clamp(camera_radiance(cp), vec3(0.0f), vec3(1.0f)) : vec3(0.0f);
  bool measured = dp.x >= 0 && depth_value(uint(dp.y * frame.color_depth_size.z + dp.x)) != 0u;
  return vec4(albedo, measured ? 1.0f : 0.0f);
}
#endif
#endif  // MRGI_UPLOAD_COLOR_ONLY

#endif  // MRGI_UPLOAD_GATHER_GLSL
