#version 450
// A voxel light volume's finest level from the injected flux sums (gi/voxel_light.h,
// voxel_inject.comp): radiance premultiplied by coverage, sum / (pi s^2), negative where a
// delta volume lost light.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer cells;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image3D light;
layout(push_constant) uniform ResolveParams {
  ivec4 cells_per_side;  // x
  vec4 scale;            // x: 1 / (pi s^2), s the voxel size (m)
} params_block;

void main() {
  const int n = params_block.cells_per_side.x;  // copied first: MRGI_UNIFORM_COPIES
  const float scale = params_block.scale.x;
  const ivec3 c = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(c, ivec3(n)))) return;
  const int base = ((c.z * n + c.y) * n + c.x) * 3;
  const vec3 flux = vec3(imageLoad(cells, base).x, imageLoad(cells, base + 1).x, imageLoad(cells, base + 2).x);
  // Half floats end at 65504: a lamp bright enough to pass it saturates instead of making inf.
  imageStore(light, c, vec4(clamp(flux * scale, vec3(-65000.0), vec3(65000.0)), 0.0));
}
