#version 460
// ssrt depth filter, pass 1: D' (paper Sec. 4, eq. 1-3), the merge of the raw depth D_c with the
// depth ray-cast from the fused volume D_v, at the internal resolution. CPU reference and the
// reading of k / sub-sampling / even medians: runtime/src/technique/ssrt/depth_filter.{h,cpp}.
//   D_c valid:   D_v where both agree within lambda_D, else D_c            (cases 1, 2)
//   D_c missing: over the 5x5 sub-sampled taps q of the k x k window with a valid D_c(q) and
//                |I_c(p) - I_c(q)| < lambda_I (Omega_I, eq. 1): D_v(p) when D_v(p) is a surface
//                and at least half of them agree with the volume (Omega_D, eq. 2), else their
//                lower median, else 0 (missing)                            (cases 3, 4)
// Inputs per pixel from depth_input.comp. Writes D' twice: alone (R32F, the chain's D') and
// with I_c (RG32F) so the bilateral pass fetches one texel per tap.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rg32f) readonly uniform image2D depth_input;   // D_c, I_c + agree
layout(set = 0, binding = 2, r32f) readonly uniform image2D depth_volume;   // D_v, m, 0 = none
layout(set = 0, binding = 3, r32f) writeonly uniform image2D merged;        // D'
layout(set = 0, binding = 4, rg32f) writeonly uniform image2D merged_intensity;  // D', I_c
// window: x tap reach (pixels), y tap stride (pixels), z taps per side (<= 5, odd), w 1 when
// depth_volume holds D_v. thresholds: x lambda_I (grey levels), y lambda_D (metres).
struct PushConstants { ivec4 window; vec4 thresholds; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

float volume_depth(ivec2 pixel) {
  if (pc.window.w == 0) return 0.0f;
  float z = imageLoad(depth_volume, pixel).x;
  return depth_valid(z) ? z : 0.0f;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 size = frame.internal_output_size.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  vec2 centre = imageLoad(depth_input, pixel).xy;
  float d_c = centre.x;
  float i_p = mod(centre.y, 256.0f);
  float result = d_c;
  if (d_c > 0.0f) {  // cases 1 and 2
    if (centre.y >= 256.0f) result = volume_depth(pixel);
  } else {
    // Cases 3 and 4 over the sub-sampled window: taps (i - 2) * stride, |i - 2| <= half.
    int half_taps = pc.window.z / 2, stride = pc.window.y;
    float v[25];
    int n_i = 0, n_d = 0;
    [[unroll]] for (int ty = 0; ty < 5; ++ty) {
      [[unroll]] for (int tx = 0; tx < 5; ++tx) {
        // Branch-free (SIMD lanes stay together): fetch a clamped texel, then mask.
        ivec2 q = pixel + ivec2(tx - 2, ty - 2) * stride;
        bool in_window = abs(tx - 2) <= half_taps && abs(ty - 2) <= half_taps &&
                         all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
        vec2 t = imageLoad(depth_input, clamp(q, ivec2(0), size - 1)).xy;
        bool use = in_window && t.x > 0.0f && abs(i_p - mod(t.y, 256.0f)) < pc.thresholds.x;
        v[ty * 5 + tx] = use ? t.x : MRGI_DEPTH_EXCLUDED;  // Omega_I
        n_i += use ? 1 : 0;
        n_d += use && t.y >= 256.0f ? 1 : 0;               // Omega_D
      }
    }
    float d_v = volume_depth(pixel);
    result = 0.0f;
    if (d_v > 0.0f && 2 * n_d >= n_i) {
      result = d_v;
    } else if (n_i > 0) {
      result = lower_median25(v, n_i);
    }
  }
  imageStore(merged, pixel, vec4(result));
  imageStore(merged_intensity, pixel, vec4(result, i_p, 0.0f, 0.0f));
}
