#version 460
// dir: the geometry-aware merge, second half (merge_rows.comp has the first): each pixel averages
// the row-merged indirect light of the `side` pixels of its column around it on its own surface
// (packed with its key, indirect_pack.glsl); baseline's shading pass adds it to both solutions
// (shade_direct.comp kVolumeBounce bit 8), up-sampled where it is at a lower resolution.
#extension GL_GOOGLE_include_directive : require
#include "dir/dir_params.glsl"
#include "dir/indirect_pack.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D rows;
layout(set = 0, binding = 1, rgba32ui) writeonly uniform uimage2D merged;
layout(push_constant) uniform Params { DirParams params_block; };
DirParams params;

void main() {
  params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 extent = params.extent.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, extent))) return;
  uvec4 centre = imageLoad(rows, pixel);
  if (centre.w == 0u) {  // no surface: nothing shaded here
    imageStore(merged, pixel, uvec4(0u));
    return;
  }
  vec3 rv = vec3(0.0f), r = vec3(0.0f);
  float weight = 0.0f;
  int side = max(params.vpls.w, 1), lo = -(side / 2);
  for (int y = lo; y < lo + side; ++y) {
    ivec2 q = ivec2(pixel.x, clamp(pixel.y + y, 0, extent.y - 1));
    uvec4 t = y == 0 ? centre : imageLoad(rows, q);
    if (!same_surface(centre.w, t.w)) continue;
    rv += unpack_indirect_rv(t);
    r += unpack_indirect_r(t);
    weight += 1.0f;
  }
  float k = 1.0f / max(weight, 1.0f);
  imageStore(merged, pixel, pack_indirect(rv * k, r * k, vec3(0.0f), 0.0f, false) & uvec4(~0u, ~0u, ~0u, 0u) |
                            uvec4(0u, 0u, 0u, centre.w));
}
