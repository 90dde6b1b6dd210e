#version 460
// ssrt depth filter, pass 1: D' (paper Sec. 4, eq. 1-3), the merge of the raw depth D_c with the
// depth ray-cast from the fused volume D_v, at the internal resolution. CPU reference and the
// reading of k / sub-sampling / even medians: runtime/src/technique/ssrt/depth_filter.{h,cpp}.
//   D_c valid:   D_v where both agree within lambda_D, else D_c            (cases 1, 2)
//   D_c missing: over the 5x5 sub-sampled taps q of the k x k window with a valid D_c(q) and
//                |I_c(p) - I_c(q)| < lambda_I (Omega_I, eq. 1): D_v(p) when D_v(p) is a surface
//                and at least half of them agree with the volume (Omega_D, eq. 2), else their
//                lower median, else 0 (missing)                            (cases 3, 4)
// Also writes I_c (grey 0..255) for the bilateral pass, so the colour is decoded once.
//
// D_c and I_c come from this frame's upload buffers by the same per-pixel gather as
// recon/depth_to_positions.comp: the internal pixel's ray -> nearest depth / colour sample
// (identity when registered at full resolution; never interpolated across depth edges).
// The window is read from a shared-memory tile: each workgroup gathers its 16 x 16 pixels plus
// the tap reach once, instead of every missing pixel fetching 25 taps from the buffers.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

#define GROUP 16
#define MAX_REACH 16                       // pixels; DepthFilterGpu::create checks the settings
#define TILE_CAP ((GROUP + 2 * MAX_REACH) * (GROUP + 2 * MAX_REACH))

layout(local_size_x = GROUP, local_size_y = GROUP) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(std430, set = 0, binding = 1) readonly buffer ColorWords { uint color_words[]; };  // RGB8
layout(std430, set = 0, binding = 2) readonly buffer DepthWords { uint depth_words[]; };  // u16
layout(set = 0, binding = 3, r32f) readonly uniform image2D depth_volume;   // D_v, m, 0 = none
layout(set = 0, binding = 4, r32f) writeonly uniform image2D merged;        // D'
layout(set = 0, binding = 5, r32f) writeonly uniform image2D intensity;     // I_c, 0..255
// window: x tap reach (pixels, <= MAX_REACH), y tap stride (pixels), z taps per side (<= 5,
// odd), w 1 when depth_volume holds D_v (else it is a placeholder and every D_v is missing).
// thresholds: x lambda_I (grey levels), y lambda_D (metres).
layout(push_constant) uniform Push { ivec4 window; vec4 thresholds; } pc;

shared float s_depth[TILE_CAP];  // D_c, 0 = missing or outside the image
shared uint s_meta[TILE_CAP];    // bits 0..7: I_c; bit 8: D_c and D_v agree (|D_c - D_v| < lambda_D)

uint color_byte(uint index) { return (color_words[index >> 2] >> ((index & 3u) * 8u)) & 0xffu; }
uint depth_value(uint index) { return (depth_words[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu; }

// Nearest pixel of a camera with intrinsics k and size for a camera-space ray; (-1, -1) outside.
ivec2 nearest_pixel(vec3 ray, vec4 k, ivec2 size) {
  vec2 p = project_pinhole(ray, k);
  ivec2 q = ivec2(floor(p + 0.5));
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return ivec2(-1);
  return q;
}

// Grey level of an sRGB8 colour: Rec. 601 luma on the encoded bytes in 8-bit fixed point,
// (77 R + 150 G + 29 B + 128) >> 8 (weights sum to 256: white stays 255). Integer, so the CPU
// reference is fed exactly the same value (DepthFilterGpu::grey_level).
uint grey_at(ivec2 pixel, ivec2 color_size) {
  vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);
  ivec2 cp = nearest_pixel(ray, frame.color_k, color_size);
  if (cp.x < 0) return 0u;
  uint base = uint(cp.y * color_size.x + cp.x) * 3u;
  return (77u * color_byte(base) + 150u * color_byte(base + 1u) + 29u * color_byte(base + 2u) +
          128u) >> 8;
}

float camera_depth_at(ivec2 pixel, ivec2 depth_size) {
  vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);
  ivec2 dp = nearest_pixel(ray, frame.depth_k, depth_size);
  if (dp.x < 0) return 0.0f;
  uint raw = depth_value(uint(dp.y * depth_size.x + dp.x));
  float z = float(raw) / frame.camera.x;
  return raw != 0u && depth_valid(z) ? z : 0.0f;
}

float volume_depth_at(ivec2 pixel) {
  if (pc.window.w == 0) return 0.0f;
  float z = imageLoad(depth_volume, pixel).x;
  return depth_valid(z) ? z : 0.0f;
}

void main() {
  ivec2 size = frame.internal_output_size.xy;
  ivec2 color_size = frame.color_depth_size.xy;
  ivec2 depth_size = frame.color_depth_size.zw;
  int reach = pc.window.x;
  int tile_w = GROUP + 2 * reach;
  ivec2 tile_origin = ivec2(gl_WorkGroupID.xy) * GROUP - reach;
  for (int i = int(gl_LocalInvocationIndex); i < tile_w * tile_w; i += GROUP * GROUP) {
    ivec2 q = tile_origin + ivec2(i % tile_w, i / tile_w);
    float d_c = 0.0f;
    uint meta = 0u;
    if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))) {
      d_c = camera_depth_at(q, depth_size);
      float d_v = volume_depth_at(q);
      bool agree = d_c > 0.0f && d_v > 0.0f && abs(d_c - d_v) < pc.thresholds.y;
      meta = grey_at(q, color_size) | (agree ? 0x100u : 0u);
    }
    s_depth[i] = d_c;
    s_meta[i] = meta;
  }
  barrier();

  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  ivec2 local = ivec2(gl_LocalInvocationID.xy) + reach;
  int centre = local.y * tile_w + local.x;
  float d_c = s_depth[centre];
  float i_p = float(s_meta[centre] & 0xffu);
  imageStore(intensity, pixel, vec4(i_p, 0.0f, 0.0f, 0.0f));
  float d_v = volume_depth_at(pixel);
  if (d_c > 0.0f) {  // cases 1 and 2
    imageStore(merged, pixel, vec4((s_meta[centre] & 0x100u) != 0u ? d_v : d_c));
    return;
  }

  // Cases 3 and 4 over the sub-sampled window: taps (i - 2) * stride, |i - 2| <= half.
  int half_taps = pc.window.z / 2, stride = pc.window.y;
  float v[25];
  int n_i = 0, n_d = 0;
  [[unroll]] for (int ty = 0; ty < 5; ++ty) {
    [[unroll]] for (int tx = 0; tx < 5; ++tx) {
      float d = MRGI_DEPTH_EXCLUDED;
      if (abs(tx - 2) <= half_taps && abs(ty - 2) <= half_taps) {
        ivec2 t = local + ivec2(tx - 2, ty - 2) * stride;
        int q = t.y * tile_w + t.x;
        float d_q = s_depth[q];
        uint meta = s_meta[q];
        if (d_q > 0.0f && abs(i_p - float(meta & 0xffu)) < pc.thresholds.x) {  // Omega_I
          d = d_q;
          ++n_i;
          n_d += int(meta >> 8);  // Omega_D
        }
      }
      v[ty * 5 + tx] = d;
    }
  }
  float result = 0.0f;
  if (d_v > 0.0f && 2 * n_d >= n_i) {
    result = d_v;
  } else if (n_i > 0) {
    result = lower_median25(v, n_i);
  }
  imageStore(merged, pixel, vec4(result));
}
