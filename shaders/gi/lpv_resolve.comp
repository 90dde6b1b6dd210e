#version 450
// The injected sums (12 floats a cell, gi/lpv_inject.comp) as the volume's first step: one
// RGBA32F image per colour channel, and the same into the accumulation (the propagated light
// adds to what was injected).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer cells;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image3D step_r;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image3D step_g;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image3D step_b;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image3D sum_r;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image3D sum_g;
layout(set = 0, binding = 6, rgba32f) uniform writeonly image3D sum_b;
layout(push_constant) uniform ResolveParams {
  ivec4 cells_per_side;  // x: used, y: allocated
} params_block;

vec4 load4(int base) {
  return vec4(imageLoad(cells, base).x, imageLoad(cells, base + 1).x, imageLoad(cells, base + 2).x,
              imageLoad(cells, base + 3).x);
}

void main() {
  const int n = params_block.cells_per_side.x;  // copied first: MRGI_UNIFORM_COPIES
  const int allocated = params_block.cells_per_side.y;
  const ivec3 c = ivec3(gl_GlobalInvocationID);
  if (any(greaterThan(c, ivec3(n)))) return;
  if (any(equal(c, ivec3(n)))) {
    // The layer of cells just past the used corner: a trilinear lookup at the last used cell's
    // centre gives them weight 0, and 0 x NaN is NaN, so they must hold finite values, whatever
    // the memory held before (nothing else writes them while this size is in use).
    if (n < allocated) {
      imageStore(sum_r, c, vec4(0.0));
      imageStore(sum_g, c, vec4(0.0));
      imageStore(sum_b, c, vec4(0.0));
    }
    return;
  }
  const int base = ((c.z * n + c.y) * n + c.x) * 12;
  const vec4 r = load4(base), g = load4(base + 4), b = load4(base + 8);
  imageStore(step_r, c, r);
  imageStore(step_g, c, g);
  imageStore(step_b, c, b);
  imageStore(sum_r, c, r);
  imageStore(sum_g, c, g);
  imageStore(sum_b, c, b);
}
