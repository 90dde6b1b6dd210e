#version 450
// The visibility volume's finest level from the voxelisation sums (gi/voxelize.h): a voxel any
// surface sample fell in is occupied (occlusion 1, Sec. 3.2: "set to 1 for every voxel that has
// geometry in it and 0 otherwise") and holds the area-weighted mean of its surfaces' unit
// normals, premultiplied by the occupancy (shaders/shared/vct_math.h
// vct_directional_occlusion reads it so; the mip chain's plain mean keeps it so).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer cells;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image3D visibility;
layout(push_constant) uniform ResolveParams {
  ivec4 cells_per_side;  // x
} params_block;

void main() {
  const int n = params_block.cells_per_side.x;  // copied first: MRGI_UNIFORM_COPIES
  const ivec3 c = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(c, ivec3(n)))) return;
  const int base = ((c.z * n + c.y) * n + c.x) * 4;
  const float area = imageLoad(cells, base + 3).x;
  vec4 v = vec4(0.0);
  if (area > 0.0) {
    const vec3 sum = vec3(imageLoad(cells, base + 0).x, imageLoad(cells, base + 1).x, imageLoad(cells, base + 2).x);
    v = vec4(sum / area, 1.0);
  }
  imageStore(visibility, c, v);
}
