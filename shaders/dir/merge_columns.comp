#version 460
// dir: the geometry-aware merge, second half (merge_rows.comp has the first; the averaging is
// dir/merge_column.glsl's): each pixel averages the row-merged indirect light of the `side`
// pixels of its column around it on its own surface (packed with its key, indirect_pack.glsl);
// the direct-light block's shading pass adds it to both solutions (shading/direct_light.comp, its screen input),
// up-sampled where it is at a lower resolution. Only without temporal smoothing: temporal.comp
// merges the column itself.
#extension GL_GOOGLE_include_directive : require
#include "dir/dir_params.glsl"
#include "gi/indirect_pack.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D rows;
layout(set = 0, binding = 1, rgba32ui) writeonly uniform uimage2D merged;
layout(push_constant) uniform Params { DirParams params_block; };
DirParams params;
#include "dir/merge_column.glsl"

void main() {
  params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 extent = params.extent.xy;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, extent))) return;
  imageStore(merged, pixel, merge_column(pixel, extent, params.vpls.w));
}
