#version 450
// One level of an importance pyramid (gi/vpl.h): each texel the sum of its four children, every
// channel (importance and covered texels). Hierarchical warping (mrgi_shared.h warp_step) reads
// the children's values back down the pyramid, so sums, not means.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D finer;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D coarser;
layout(push_constant) uniform Params {
  ivec4 size;  // x: the coarser level's used side
} params;

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  ivec2 c = t * 2;
  vec4 sum = imageLoad(finer, c) + imageLoad(finer, c + ivec2(1, 0)) + imageLoad(finer, c + ivec2(0, 1)) +
             imageLoad(finer, c + ivec2(1, 1));
  imageStore(coarser, t, sum);
}
