#version 460
// The real caster mesh's index buffer for this frame (DIR paper section 4.3: the real scene as
// the depth camera sees it, rasterised into the shadow maps). Vertices are the points of a grid
// over the G-buffer, one every `stride` pixels (shadow_depth_grid.vert reads each once); each
// grid cell gives two triangles. A triangle with an invalid vertex (no depth) or spanning a
// depth discontinuity (MRGI_DEPTH_EDGE_RELATIVE) is written as three copies of one index: zero
// area, culled at triangle setup. Run once a frame and shared by every shadow map face, so the
// validity test costs one pass instead of one per face, and the draw is indexed: each grid
// point is shaded once instead of six times (the non-indexed grid read 18 texels a cell).
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D real_position;  // xyz world, w depth (0 invalid)
layout(std430, set = 0, binding = 1) writeonly buffer Indices { uint indices[]; };
struct GridConstants {
  ivec4 grid;  // x, y: grid points per row / column; z: G-buffer pixels between points
};
layout(push_constant) uniform Grid { GridConstants params_block; };
GridConstants params;

void main() {
  params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  ivec2 cells = params.grid.xy - 1;
  if (any(greaterThanEqual(q, cells))) return;
  int stride = params.grid.z;
  float z00 = texelFetch(real_position, q * stride, 0).w;
  float z10 = texelFetch(real_position, (q + ivec2(1, 0)) * stride, 0).w;
  float z01 = texelFetch(real_position, (q + ivec2(0, 1)) * stride, 0).w;
  float z11 = texelFetch(real_position, (q + ivec2(1, 1)) * stride, 0).w;
  uint row = uint(params.grid.x);
  uint i00 = uint(q.y) * row + uint(q.x), i10 = i00 + 1u, i01 = i00 + row, i11 = i01 + 1u;
  uint base = (uint(q.y) * uint(cells.x) + uint(q.x)) * 6u;
  bool a = mrgi_one_surface(z00, z10, z01), b = mrgi_one_surface(z10, z11, z01);
  indices[base + 0u] = i00;
  indices[base + 1u] = a ? i10 : i00;
  indices[base + 2u] = a ? i01 : i00;
  indices[base + 3u] = i10;
  indices[base + 4u] = b ? i11 : i10;
  indices[base + 5u] = b ? i01 : i10;
}
