#version 460
// ssrt depth filter, pass 0: this frame's raw inputs at the internal resolution, once per pixel,
// for the merge's 25-tap windows: D_c (metres, 0 = missing) and I_c (grey 0..255) gathered from
// the upload buffers, and whether D_c agrees with the volume (|D_c - D_v| < lambda_D, both
// valid: the Omega_D test of eq. 2).
// The gather is recon/depth_to_positions.comp's (common/upload_gather.glsl): the internal
// pixel's ray -> nearest depth / colour sample (identity when registered at full resolution).
// Why a pass of its own: on lavapipe every tap of the merge would otherwise redo this gather
// (projection, three byte loads, a volume fetch) 25 times, and shared-memory tiles cost more
// than they save there (a barrier makes every SIMD chunk of the workgroup a coroutine).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require  // depth_median.glsl
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, r32f) readonly uniform image2D depth_volume;  // D_v, m, 0 = none
// x: D_c (metres, 0 = missing); y: I_c + 256 when D_c and D_v agree.
layout(set = 0, binding = 4, rg32f) writeonly uniform image2D depth_input;
// window.w: 1 when depth_volume holds D_v (else a placeholder: every D_v is missing);
// thresholds.y: lambda_D (metres). (The merge's push block; the other fields are unused here.)
struct PushConstants { ivec4 window; vec4 thresholds; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  ivec2 color_size = frame.color_depth_size.xy;
  ivec2 depth_size = frame.color_depth_size.zw;
  vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);

  float d_c = 0.0f;
  ivec2 dp = nearest_pixel(ray, frame.depth_k, depth_size);
  if (dp.x >= 0) {
    uint raw = depth_value(uint(dp.y * depth_size.x + dp.x));
    float z = float(raw) / frame.camera.x;
    if (raw != 0u && depth_valid(z)) d_c = z;
  }
  // Grey level of the sRGB8 colour: Rec. 601 luma on the encoded bytes in 8-bit fixed point,
  // (77 R + 150 G + 29 B + 128) >> 8 (weights sum to 256: white stays 255). Integer, so the
  // CPU reference is fed exactly the same value (ssrt::grey_level).
  uint grey = 0u;
  ivec2 cp = nearest_pixel(ray, frame.color_k, color_size);
  if (cp.x >= 0) {
    uvec3 c = color_rgb8(uint(cp.y * color_size.x + cp.x));
    grey = (77u * c.x + 150u * c.y + 29u * c.z + 128u) >> 8;
  }
  bool agree = false;
  if (d_c > 0.0f && pc.window.w != 0) {
    float d_v = imageLoad(depth_volume, pixel).x;
    agree = depth_valid(d_v) && abs(d_c - d_v) < pc.thresholds.y;
  }
  imageStore(depth_input, pixel, vec4(d_c, float(grey + (agree ? 256u : 0u)), 0.0f, 0.0f));
}
