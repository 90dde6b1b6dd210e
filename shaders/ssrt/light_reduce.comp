#version 460
// ssrt light estimation, step 1 of 2 (paper Sec. 5.2): the normal equations of T l = I_c summed
// over one tile of 16 x 12 cells. Row k of the workgroup's partial sum:
//   k < 136        (T^T T)_ij over the upper triangle i <= j, row-major
//   136 <= k < 184 (T^T I_c)_ic, i = (k - 136) / 3, c = (k - 136) % 3
//   k == 184       number of cells used; 185..191 zero padding
// Only usable cells count (a real surface, camera colour below saturation: coarse layer 4 z).
// Each thread loads one cell, then computes one entry over the whole tile, so no atomics and no
// float-atomic extension are needed and the sum order is fixed (deterministic results).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(local_size_x = 16, local_size_y = 12) in;
layout(set = 0, binding = 0) uniform sampler2DArray coarse;
layout(set = 0, binding = 1) uniform sampler2D real_albedo;  // the camera colour, linear
layout(std430, set = 0, binding = 2) writeonly buffer Partials { float partials[]; };
layout(push_constant) uniform Push {
  ivec4 grid;  // x, y cells; z step in pixels; w tiles per row
} pc;

const int kEntries = 192;
shared float tile_t[192][16];
shared vec3 tile_i[192];
shared float tile_ok[192];

void main() {
  int local = int(gl_LocalInvocationIndex);
  ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(real_albedo, 0);
  bool inside = cell.x < pc.grid.x && cell.y < pc.grid.y;
  float ok = 0.0f;
  vec3 camera = vec3(0.0f);
  if (inside) {
    ok = texelFetch(coarse, ivec3(cell, 4), 0).z;
    ivec2 pixel = min(cell * pc.grid.z + ivec2(pc.grid.z / 2), size - ivec2(1));
    camera = texelFetch(real_albedo, pixel, 0).rgb;
  }
  for (int c = 0; c < 4; ++c) {
    vec4 t = ok > 0.5f ? texelFetch(coarse, ivec3(cell, c), 0) : vec4(0.0f);
    tile_t[local][4 * c + 0] = t.x;
    tile_t[local][4 * c + 1] = t.y;
    tile_t[local][4 * c + 2] = t.z;
    tile_t[local][4 * c + 3] = t.w;
  }
  tile_i[local] = ok > 0.5f ? camera : vec3(0.0f);
  tile_ok[local] = ok > 0.5f ? 1.0f : 0.0f;
  barrier();

  int k = local;
  float sum = 0.0f;
  if (k < 136) {
    // Upper-triangle index -> (i, j).
    int i = 0, rest = k;
    while (rest >= 16 - i) { rest -= 16 - i; ++i; }
    int j = i + rest;
    for (int p = 0; p < 192; ++p) sum += tile_t[p][i] * tile_t[p][j];
  } else if (k < 184) {
    int i = (k - 136) / 3, c = (k - 136) % 3;
    for (int p = 0; p < 192; ++p) sum += tile_t[p][i] * (c == 0 ? tile_i[p].r : (c == 1 ? tile_i[p].g : tile_i[p].b));
  } else if (k == 184) {
    for (int p = 0; p < 192; ++p) sum += tile_ok[p];
  }
  int group = int(gl_WorkGroupID.y) * pc.grid.w + int(gl_WorkGroupID.x);
  partials[group * kEntries + k] = sum;
}
