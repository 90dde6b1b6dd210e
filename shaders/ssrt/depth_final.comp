#version 460
// ssrt depth filter, pass 3: D''' (paper Sec. 4, eq. 5), a plain median of D'' over every pixel
// of a small window (k = 2 -> 3 x 3; up to 5 x 5): the lower median of the valid depths, 0 when
// there are none. It removes the single-pixel noise the sub-sampled medians leave.
// CPU reference: runtime/src/technique/ssrt/depth_filter.cpp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

#define GROUP 16
#define MAX_RADIUS 2
#define TILE_CAP ((GROUP + 2 * MAX_RADIUS) * (GROUP + 2 * MAX_RADIUS))

layout(local_size_x = GROUP, local_size_y = GROUP) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) readonly uniform image2D bilateral;    // D''
layout(set = 0, binding = 2, r32f) writeonly uniform image2D final_depth; // D'''
layout(push_constant) uniform Push { ivec4 window; } pc;  // x: radius (0..2 pixels)

shared float s_depth[TILE_CAP];

void main() {
  ivec2 size = frame.internal_output_size.xy;
  int radius = pc.window.x;
  int tile_w = GROUP + 2 * radius;
  ivec2 tile_origin = ivec2(gl_WorkGroupID.xy) * GROUP - radius;
  for (int i = int(gl_LocalInvocationIndex); i < tile_w * tile_w; i += GROUP * GROUP) {
    ivec2 q = tile_origin + ivec2(i % tile_w, i / tile_w);
    float d = MRGI_DEPTH_EXCLUDED;
    if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))) {
      d = imageLoad(bilateral, q).x;
      if (!depth_valid(d)) d = MRGI_DEPTH_EXCLUDED;
    }
    s_depth[i] = d;
  }
  barrier();

  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  ivec2 local = ivec2(gl_LocalInvocationID.xy) + radius;
  float result = 0.0f;
  if (radius == 0) {
    float d = s_depth[local.y * tile_w + local.x];
    result = d < MRGI_DEPTH_EXCLUDED ? d : 0.0f;
  } else if (radius == 1) {
    float v[9];
    int n = 0;
    [[unroll]] for (int i = 0; i < 9; ++i) {
      v[i] = s_depth[(local.y + i / 3 - 1) * tile_w + local.x + i % 3 - 1];
      n += v[i] < MRGI_DEPTH_EXCLUDED ? 1 : 0;
    }
    if (n > 0) result = lower_median9(v, n);
  } else {
    float v[25];
    int n = 0;
    [[unroll]] for (int i = 0; i < 25; ++i) {
      v[i] = s_depth[(local.y + i / 5 - 2) * tile_w + local.x + i % 5 - 2];
      n += v[i] < MRGI_DEPTH_EXCLUDED ? 1 : 0;
    }
    if (n > 0) result = lower_median25(v, n);
  }
  imageStore(final_depth, pixel, vec4(result));
}
