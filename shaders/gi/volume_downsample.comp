#version 450
// One level of a volume's mip chain (runtime/src/gi/volume.h): each cell of level i is the mean of
// the 2 x 2 x 2 cells of level i - 1 it covers (cells beyond the coarser level's used extent are
// clamped to its last cell, so an odd size keeps its border). The volumes hold premultiplied
// values (radiance x opacity, or SH coefficients), for which the plain mean is the right filter.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, rgba16f) uniform readonly image3D finer;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image3D coarser;
layout(push_constant) uniform DownsampleParams {
  ivec4 finer_extent;    // used cells of level i - 1 (xyz)
  ivec4 coarser_extent;  // used cells of level i (xyz)
} params_block;

void main() {
  const ivec4 finer_extent = params_block.finer_extent;  // copied first: MRGI_UNIFORM_COPIES
  const ivec4 coarser_extent = params_block.coarser_extent;
  const ivec3 p = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(p, coarser_extent.xyz))) return;
  const ivec3 last = finer_extent.xyz - 1;
  vec4 sum = vec4(0.0);
  for (int k = 0; k < 8; ++k) {
    const ivec3 o = ivec3(k & 1, (k >> 1) & 1, k >> 2);
    sum += imageLoad(finer, min(2 * p + o, last));
  }
  imageStore(coarser, p, sum * 0.125);
}
