#version 460
// dir: the geometry-aware merge of the interleaved VPL shading (shade_vpl.comp; the DIR paper's
// "merging" after its 4x4 split, Segovia et al. 2006), first half: each pixel averages the
// indirect light of the `side` pixels of its row around it (offsets -side/2 .. side/2 - 1: every
// column residue once) that lie on its own surface (indirect_pack.glsl same_surface). Separable:
// merge_columns.comp then averages these over the column, so every pixel combines all side^2
// VPL subsets with 2 side taps instead of side^2 (a cross-bilateral filter, split in two).
#extension GL_GOOGLE_include_directive : require
#include "dir/dir_params.glsl"
#include "gi/indirect_pack.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D indirect;
layout(set = 0, binding = 1, rgba32ui) writeonly uniform uimage2D rows;
layout(push_constant) uniform Params { DirParams params_block; };
DirParams params;

void main() {
  params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 extent = params.extent.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, extent))) return;
  uvec4 centre = imageLoad(indirect, pixel);
  vec3 rv = vec3(0.0f), r = vec3(0.0f);
  float weight = 0.0f;
  int side = max(params.vpls.w, 1), lo = -(side / 2);
  for (int x = lo; x < lo + side; ++x) {
    ivec2 q = ivec2(clamp(pixel.x + x, 0, extent.x - 1), pixel.y);
    uvec4 t = x == 0 ? centre : imageLoad(indirect, q);
    if (!same_surface(centre.w, t.w)) continue;
    rv += unpack_indirect_rv(t);
    r += unpack_indirect_r(t);
    weight += 1.0f;
  }
  float k = 1.0f / max(weight, 1.0f);
  imageStore(rows, pixel, pack_indirect(rv * k, r * k, vec3(0.0f), 0.0f, false) & uvec4(~0u, ~0u, ~0u, 0u) |
                          uvec4(0u, 0u, 0u, centre.w));
}
