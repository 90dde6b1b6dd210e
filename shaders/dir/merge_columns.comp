#version 460
// dir: the geometry-aware merge, second half (merge_rows.comp has the first): each pixel averages
// the row-merged indirect light of the `side` pixels of its column around it on its own surface,
// and adds it to the solutions baseline's direct light wrote (L_rv, L_r).
#extension GL_GOOGLE_include_directive : require
#include "dir/dir_params.glsl"
#include "dir/indirect_pack.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D rows;
layout(set = 0, binding = 1, rgba16f) uniform image2D lit_rv;
layout(set = 0, binding = 2, rgba16f) uniform image2D lit_r;
layout(push_constant) uniform Params { DirParams params_block; ivec4 size; };
DirParams params;

void main() {
  params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 extent = size.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, extent))) return;
  uvec4 centre = imageLoad(rows, pixel);
  if (centre.w == 0u) return;  // no surface: nothing shaded here
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
  vec4 old_rv = imageLoad(lit_rv, pixel), old_r = imageLoad(lit_r, pixel);
  imageStore(lit_rv, pixel, vec4(clamp(old_rv.rgb + rv * k, vec3(0.0f), vec3(60000.0f)), old_rv.a));
  imageStore(lit_r, pixel, vec4(clamp(old_r.rgb + r * k, vec3(0.0f), vec3(60000.0f)), old_r.a));
}
