#version 460
// ssrt depth filter, pass 2: D'' (paper Sec. 4, eq. 4), the joint bilateral median of D' over
// Omega_I: the lower median of the valid D'(q) on the 5x5 sub-sampled taps of the k x k window
// whose grey level is within lambda_I of the centre's; with no such tap, D'(p) unchanged.
// Runs on every pixel: it moves depth edges onto colour edges and fills holes of D' from the
// centre's colour side. CPU reference: runtime/src/technique/ssrt/depth_filter.cpp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rg32f) readonly uniform image2D merged_intensity;  // D', I_c
layout(set = 0, binding = 2, r32f) writeonly uniform image2D bilateral;         // D''
// window: x tap reach (pixels), y tap stride, z taps per side (<= 5, odd);
// thresholds: x lambda_I (grey levels).
struct PushConstants { ivec4 window; vec4 thresholds; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 size = frame.internal_output_size.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  vec2 centre = imageLoad(merged_intensity, pixel).xy;
  int half_taps = pc.window.z / 2, stride = pc.window.y;
  float v[25];
  int n = 0;
  [[unroll]] for (int ty = 0; ty < 5; ++ty) {
    [[unroll]] for (int tx = 0; tx < 5; ++tx) {
      // Branch-free (SIMD lanes stay together): fetch a clamped texel, then mask.
      ivec2 q = pixel + ivec2(tx - 2, ty - 2) * stride;
      bool in_window = abs(tx - 2) <= half_taps && abs(ty - 2) <= half_taps &&
                       all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
      vec2 t = imageLoad(merged_intensity, clamp(q, ivec2(0), size - 1)).xy;
      bool use = in_window && depth_valid(t.x) && abs(centre.y - t.y) < pc.thresholds.x;
      v[ty * 5 + tx] = use ? t.x : MRGI_DEPTH_EXCLUDED;
      n += use ? 1 : 0;
    }
  }
  float own = depth_valid(centre.x) ? centre.x : 0.0f;
  imageStore(bilateral, pixel, vec4(n > 0 ? lower_median25(v, n) : own));
}
