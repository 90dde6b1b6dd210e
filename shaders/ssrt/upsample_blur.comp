#version 460
// ssrt fast path up-sampling, step 1 of 2 (paper Sec. 5.1, OursFast: "bicubic interpolation and
// standard Gauss filtering with a kernel radius of eight"): a Gauss filter of radius 8 output
// pixels (radius / step cells, sigma = radius / 2) over the coarse shading layers 4..6, written
// packed to `upsampled` (upsampled.glsl). Only cells that see the same kind of surface as the centre (real or virtual,
// layer 4 w) carry weight: the paper's plain Gauss smeared the virtual object's own shading into
// the contact shadow around it at 4x4. The bicubic step follows in shade.comp.
#extension GL_GOOGLE_include_directive : require
#include "ssrt/upsampled.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// kRadiusCells > 0: the window's radius in cells is this constant (the level's radius / step,
// rounded up, must equal it; ssrt.cpp picks the pipeline): the taps unroll, their in-window
// tests fold away and their Gauss weights are computed once per distance instead of per tap.
// 0: the radius comes from the push constants.
layout(constant_id = 0) const int kRadiusCells = 0;
layout(set = 0, binding = 0, rgba32f) readonly uniform image2DArray coarse;
layout(set = 0, binding = 1, rgba32ui) writeonly uniform uimage2D upsampled;
struct PushConstants {
  ivec4 grid;   // x, y cells; z step in pixels
  vec4 filt;    // x radius in output pixels
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
  if (cell.x >= pc.grid.x || cell.y >= pc.grid.y) return;
  float radius_cells = pc.filt.x / float(pc.grid.z);
  int r = kRadiusCells > 0 ? kRadiusCells : int(ceil(radius_cells));
  float sigma = max(radius_cells * 0.5f, 1e-3f);
  vec4 centre = imageLoad(coarse, ivec3(cell, 4));
  vec4 acc4 = vec4(0.0f), acc5 = vec4(0.0f), acc6 = vec4(0.0f);
  float wsum = 0.0f;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      ivec2 q = cell + ivec2(dx, dy);
      if (q.x < 0 || q.y < 0 || q.x >= pc.grid.x || q.y >= pc.grid.y) continue;
      float d2 = float(dx * dx + dy * dy);
      if (d2 > radius_cells * radius_cells) continue;
      vec4 s4 = imageLoad(coarse, ivec3(q, 4));
      if (s4.w < 0.5f || abs(s4.w - centre.w) > 0.5f) continue;
      float w = exp(-0.5f * d2 / (sigma * sigma));
      acc4 += w * s4;
      acc5 += w * imageLoad(coarse, ivec3(q, 5));
      acc6 += w * imageLoad(coarse, ivec3(q, 6));
      wsum += w;
    }
  }
  bool surface = wsum > 0.0f && centre.w > 0.5f;
  vec4 s4 = surface ? acc4 / wsum : vec4(0.0f);
  vec3 s5 = surface ? acc5.xyz / wsum : vec3(0.0f), s6 = surface ? acc6.xyz / wsum : vec3(0.0f);
  imageStore(upsampled, cell,
             ssrt_pack_upsampled(s4.x, s4.y, s5, s6, surface ? centre.w : 0.0f));
}
