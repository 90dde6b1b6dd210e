#version 460
// ssrt depth filter, pass 3: D''' (paper Sec. 4, eq. 5), a plain median of D'' over every pixel
// of a small window (k = 2 -> 3 x 3; up to 5 x 5): the lower median of the valid depths, 0 when
// there are none. It removes the single-pixel noise the sub-sampled medians leave.
// CPU reference: runtime/src/technique/ssrt/depth_filter.cpp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32f) readonly uniform image2D bilateral;    // D''
layout(set = 0, binding = 2, r32f) writeonly uniform image2D final_depth; // D'''
struct PushConstants { ivec4 window; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;  // x: radius (0..2 pixels)

ivec2 g_size;

// D'' at pixel + offset, +inf (excluded) when missing or outside the image.
float tap(ivec2 pixel, ivec2 offset) {
  ivec2 q = pixel + offset;
  bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, g_size));
  float d = imageLoad(bilateral, clamp(q, ivec2(0), g_size - 1)).x;  // branch-free
  return inside && depth_valid(d) ? d : MRGI_DEPTH_EXCLUDED;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  g_size = frame.internal_output_size.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, g_size))) return;
  int radius = pc.window.x;
  float result = 0.0f;
  if (radius == 1) {
    float v[9];
    int n = 0;
    [[unroll]] for (int i = 0; i < 9; ++i) {
      v[i] = tap(pixel, ivec2(i % 3 - 1, i / 3 - 1));
      n += v[i] < MRGI_DEPTH_EXCLUDED ? 1 : 0;
    }
    if (n > 0) result = lower_median9(v, n);
  } else if (radius == 2) {
    float v[25];
    int n = 0;
    [[unroll]] for (int i = 0; i < 25; ++i) {
      v[i] = tap(pixel, ivec2(i % 5 - 2, i / 5 - 2));
      n += v[i] < MRGI_DEPTH_EXCLUDED ? 1 : 0;
    }
    if (n > 0) result = lower_median25(v, n);
  } else {
    float d = tap(pixel, ivec2(0));
    result = d < MRGI_DEPTH_EXCLUDED ? d : 0.0f;
  }
  imageStore(final_depth, pixel, vec4(result));
}
