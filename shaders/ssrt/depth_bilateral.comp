#version 460
// ssrt depth filter, pass 2: D'' (paper Sec. 4, eq. 4), the joint bilateral median of D' over
// Omega_I: the lower median of the valid D'(q) on the 5x5 sub-sampled taps of the k x k window
// whose grey level is within lambda_I of the centre's; with no such tap, D'(p) unchanged.
// Runs on every pixel: it moves depth edges onto colour edges and fills holes of D' from the
// centre's colour side. CPU reference: runtime/src/technique/ssrt/depth_filter.cpp.
// Window from a shared-memory tile (group + tap reach), as in depth_merge.comp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

#define GROUP 16
#define MAX_REACH 16                       // pixels; DepthFilterGpu::create checks the settings
#define TILE_CAP ((GROUP + 2 * MAX_REACH) * (GROUP + 2 * MAX_REACH))

layout(local_size_x = GROUP, local_size_y = GROUP) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) readonly uniform image2D merged;      // D'
layout(set = 0, binding = 2, r32f) readonly uniform image2D intensity;   // I_c, 0..255
layout(set = 0, binding = 3, r32f) writeonly uniform image2D bilateral;  // D''
// window: x tap reach (pixels, <= MAX_REACH), y tap stride, z taps per side (<= 5, odd);
// thresholds: x lambda_I (grey levels).
layout(push_constant) uniform Push { ivec4 window; vec4 thresholds; } pc;

shared float s_depth[TILE_CAP];      // D', 0 = missing or outside the image
shared float s_intensity[TILE_CAP];

void main() {
  ivec2 size = frame.internal_output_size.xy;
  int reach = pc.window.x;
  int tile_w = GROUP + 2 * reach;
  ivec2 tile_origin = ivec2(gl_WorkGroupID.xy) * GROUP - reach;
  for (int i = int(gl_LocalInvocationIndex); i < tile_w * tile_w; i += GROUP * GROUP) {
    ivec2 q = tile_origin + ivec2(i % tile_w, i / tile_w);
    float d = 0.0f, g = 0.0f;
    if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))) {
      d = imageLoad(merged, q).x;
      g = imageLoad(intensity, q).x;
      if (!depth_valid(d)) d = 0.0f;
    }
    s_depth[i] = d;
    s_intensity[i] = g;
  }
  barrier();

  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  ivec2 local = ivec2(gl_LocalInvocationID.xy) + reach;
  int centre = local.y * tile_w + local.x;
  float i_p = s_intensity[centre];
  int half_taps = pc.window.z / 2, stride = pc.window.y;
  float v[25];
  int n = 0;
  [[unroll]] for (int ty = 0; ty < 5; ++ty) {
    [[unroll]] for (int tx = 0; tx < 5; ++tx) {
      float d = MRGI_DEPTH_EXCLUDED;
      if (abs(tx - 2) <= half_taps && abs(ty - 2) <= half_taps) {
        ivec2 t = local + ivec2(tx - 2, ty - 2) * stride;
        int q = t.y * tile_w + t.x;
        float d_q = s_depth[q];
        if (d_q > 0.0f && abs(i_p - s_intensity[q]) < pc.thresholds.x) {
          d = d_q;
          ++n;
        }
      }
      v[ty * 5 + tx] = d;
    }
  }
  float result = n > 0 ? lower_median25(v, n) : s_depth[centre];
  imageStore(bilateral, pixel, vec4(result));
}
