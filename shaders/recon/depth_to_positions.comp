#version 460
// Reconstruction v0, step 1: raw depth (u16) -> view-space -> world-space positions, and the
// real albedo estimate from the camera colour, at the internal resolution.
// 0 depth = invalid; an invalid pixel is written as all zeros and stays invalid in every later
// step (normals, caster mesh, shading).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(std430, set = 0, binding = 1) readonly buffer ColorWords { uint color_words[]; };  // RGB8
layout(std430, set = 0, binding = 2) readonly buffer DepthWords { uint depth_words[]; };  // u16
layout(set = 0, binding = 3, rgba32f) writeonly uniform image2D real_position;  // xyz world, w z
layout(set = 0, binding = 4, rgba16f) writeonly uniform image2D real_albedo;    // rgb, a valid

uint color_byte(uint index) { return (color_words[index >> 2] >> ((index & 3u) * 8u)) & 0xffu; }
uint depth_value(uint index) { return (depth_words[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu; }

// Nearest pixel of a camera with intrinsics k and size for a ray direction (camera space, z=1);
// (-1, -1) outside the image.
ivec2 nearest_pixel(vec3 ray, vec4 k, ivec2 size) {
  vec2 p = project_pinhole(ray, k);
  ivec2 q = ivec2(floor(p + 0.5));
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return ivec2(-1);
  return q;
}

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 internal_size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, internal_size))) return;
  ivec2 color_size = frame.color_depth_size.xy;
  ivec2 depth_size = frame.color_depth_size.zw;

  // Colour and depth cameras share their centre and orientation (capture.json has intrinsics
  // only), so depth is brought into the colour camera by a per-pixel gather along the same ray:
  // identity when the intrinsics match, else the nearest depth sample (never interpolated,
  // which would invent depths between a foreground and a background surface).
  vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);
  ivec2 dp = nearest_pixel(ray, frame.depth_k, depth_size);
  float z = 0.0f;
  if (dp.x >= 0) {
    uint raw = depth_value(uint(dp.y * depth_size.x + dp.x));
    z = raw == 0u ? 0.0f : float(raw) / frame.camera.x;
  }
  if (!(z > 0.0f) || isinf(z)) {
    imageStore(real_position, pixel, vec4(0.0f));
    imageStore(real_albedo, pixel, vec4(0.0f));
    return;
  }
  vec4 world = frame.camera_to_world * vec4(ray * z, 1.0f);
  imageStore(real_position, pixel, vec4(world.xyz, z));

  // Albedo: the camera colour, sRGB-decoded and divided by the exposure, is used as the diffuse
  // reflectance. This is the DIR paper's approximation (section 4.3: "the diffuse intensity is
  // set to the input image color"): it is reflectance times incident light, not reflectance;
  // the differential compose divides the model out again, so the error only affects the delta.
  // Clamped to [0, 1] because a reflectance above 1 would create energy in later bounces.
  vec3 albedo = vec3(0.0f);
  ivec2 cp = nearest_pixel(ray, frame.color_k, color_size);
  if (cp.x >= 0) {
    uint base = uint(cp.y * color_size.x + cp.x) * 3u;
    vec3 encoded = vec3(color_byte(base), color_byte(base + 1u), color_byte(base + 2u)) / 255.0f;
    albedo = clamp(camera_to_radiance(encoded, frame.camera.y), vec3(0.0f), vec3(1.0f));
  }
  imageStore(real_albedo, pixel, vec4(albedo, 1.0f));
}
