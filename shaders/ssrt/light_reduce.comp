#version 460
// ssrt light estimation, step 1 of 2 (paper Sec. 5.2): the normal equations of T l = I_c summed
// over one strip of `grid.w` cells of a row per invocation. Entry k of an invocation's partial:
//   k < 136        (T^T T)_ij over the upper triangle i <= j, row-major
//   136 <= k < 184 (T^T I_c)_ic, i = (k - 136) / 3, c = (k - 136) % 3
//   k == 184       number of cells used; 185..191 zero padding
// Only usable cells count (a real surface, camera colour below saturation: coarse layer 4 z).
// Each invocation accumulates all 185 sums of its strip in registers (indices constant after
// unrolling), so the SIMD lanes work on 8 strips at once with plain multiply-adds. The previous
// form (a 16 x 12 tile in shared memory, one entry per thread over the tile) made every lane
// gather its two factors from shared memory per cell and put a barrier in the shader, which on
// lavapipe turns each SIMD chunk into a coroutine: 9 ms at 160 x 120 cells for ~3.5 M
// multiply-adds. The sum order is fixed (deterministic results).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, rgba32f) readonly uniform image2DArray coarse;
// The camera frame as uploaded (upload_gather.glsl camera_at: linear colour).
layout(std140, set = 0, binding = 3) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 4, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
#include "common/upload_gather.glsl"
layout(std430, set = 0, binding = 2) writeonly buffer Partials { float partials[]; };
struct PushConstants {
  ivec4 grid;  // x, y cells; z step in pixels; w cells per strip
  ivec4 size;  // xy the internal extent (pixels); z strips per row
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  int id = int(gl_GlobalInvocationID.x);
  int strips = pc.size.z;
  int row = id / strips;
  if (row >= pc.grid.y) return;
  int x0 = (id - row * strips) * pc.grid.w;
  float ata[136];
  float atb[48];
  [[unroll]] for (int k = 0; k < 136; ++k) ata[k] = 0.0f;
  [[unroll]] for (int k = 0; k < 48; ++k) atb[k] = 0.0f;
  float count = 0.0f;
  for (int c = 0; c < pc.grid.w; ++c) {
    ivec2 cell = ivec2(x0 + c, row);
    bool inside = cell.x < pc.grid.x;
    ivec2 q = min(cell, pc.grid.xy - ivec2(1));
    float ok = inside && imageLoad(coarse, ivec3(q, 4)).z > 0.5f ? 1.0f : 0.0f;
    ivec2 pixel = min(q * pc.grid.z + ivec2(pc.grid.z / 2), pc.size.xy - ivec2(1));
    vec3 camera = camera_at(vec2(pixel)).rgb * ok;
    float t[16];
    [[unroll]] for (int l = 0; l < 4; ++l) {
      vec4 v = imageLoad(coarse, ivec3(q, l)) * ok;
      t[4 * l + 0] = v.x;
      t[4 * l + 1] = v.y;
      t[4 * l + 2] = v.z;
      t[4 * l + 3] = v.w;
    }
    // Constant trip counts (j from 0, not from i) so both loops unroll and every index is a
    // constant: a loop starting at i kept its counter dynamic, which put ata[] in per-lane
    // scratch memory on lavapipe. k = entry (i, j) of the row-major upper triangle.
    [[unroll]] for (int i = 0; i < 16; ++i) {
      [[unroll]] for (int j = 0; j < 16; ++j) {
        if (j >= i) ata[i * 16 - (i * (i - 1)) / 2 + (j - i)] += t[i] * t[j];
      }
    }
    [[unroll]] for (int i = 0; i < 16; ++i) {
      atb[3 * i + 0] += t[i] * camera.r;
      atb[3 * i + 1] += t[i] * camera.g;
      atb[3 * i + 2] += t[i] * camera.b;
    }
    count += ok;
  }
  int base = id * 192;
  [[unroll]] for (int k = 0; k < 136; ++k) partials[base + k] = ata[k];
  [[unroll]] for (int k = 0; k < 48; ++k) partials[base + 136 + k] = atb[k];
  partials[base + 184] = count;
  [[unroll]] for (int k = 185; k < 192; ++k) partials[base + k] = 0.0f;
}
