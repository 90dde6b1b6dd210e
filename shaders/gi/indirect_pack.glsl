// dir's per-pixel indirect light and surface key in one RGBA32UI texel (shade_vpl.comp writes
// it, merge_rows.comp and merge_columns.comp read it): one load a tap for the merge, which on
// lavapipe pays per image load (the first merge, reading six images a tap, cost 5 ms at fast).
//   x, y, z: L_rv.rgb and L_r.rgb as six half floats;
//   w: low 16 bits the surface normal, octahedral, two snorm8; high 16 bits the surface's
//      camera distance as a half float, negative on virtual surfaces; 0: no surface.
#ifndef MRGI_DIR_INDIRECT_PACK_GLSL
#define MRGI_DIR_INDIRECT_PACK_GLSL
#include "shared/mrgi_shared.h"

uvec4 pack_indirect(vec3 rv, vec3 r, vec3 n, float distance_m, bool is_virtual) {
  uint normal_bits = packSnorm4x8(vec4(oct_encode(n), 0.0f, 0.0f)) & 0xffffu;
  uint depth_bits = packHalf2x16(vec2(is_virtual ? -distance_m : distance_m, 0.0f)) & 0xffffu;
  return uvec4(packHalf2x16(rv.rg), packHalf2x16(vec2(rv.b, r.r)), packHalf2x16(r.gb),
               normal_bits | (depth_bits << 16));
}
vec3 unpack_indirect_rv(uvec4 t) { return vec3(unpackHalf2x16(t.x), unpackHalf2x16(t.y).x); }
vec3 unpack_indirect_r(uvec4 t) { return vec3(unpackHalf2x16(t.y).y, unpackHalf2x16(t.z)); }

// Whether two keys are the same surface: same kind, camera distances within 5 %, normals close:
// their octahedral codes within 0.4 in L1 (about 35-60 degrees: the octahedral map stretches
// angles by up to 2x), compared without decoding (the merge tests 2 x 4 taps a pixel). Loose on
// purpose: a tap left out is a VPL subset missing from the pixel's sum, and the reconstruction's
// normals scatter by tens of degrees on flat walls (corner, high: real RDE 1.106 at 0.2, 1.005 at
// 0.4; the 4x4 pattern of the subsets showed on the walls). A key of 0 (no surface) matches nothing.
bool same_surface(uint a, uint b) {
  if (a == 0u || b == 0u) return false;
  float da = unpackHalf2x16(a >> 16).x, db = unpackHalf2x16(b >> 16).x;
  if ((da < 0.0f) != (db < 0.0f) || abs(da - db) > 0.05f * abs(da)) return false;
  vec2 d = abs(unpackSnorm4x8(a).xy - unpackSnorm4x8(b).xy);
  return d.x + d.y <= 0.4f;
}

#endif
