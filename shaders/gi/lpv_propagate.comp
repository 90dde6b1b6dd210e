#version 450
// One propagation step of a light propagation volume (gi/light_propagation.h, lpv_math.h): each
// cell gathers from its 6 neighbours' previous step through its faces, writes the new step and
// adds it to the accumulation. Neighbours outside the used volume hold no light.
#extension GL_GOOGLE_include_directive : require
#include "shared/lpv_math.h"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image3D from_r;
layout(set = 0, binding = 1, rgba32f) uniform readonly image3D from_g;
layout(set = 0, binding = 2, rgba32f) uniform readonly image3D from_b;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image3D to_r;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image3D to_g;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image3D to_b;
layout(set = 0, binding = 6, rgba32f) uniform image3D sum_r;
layout(set = 0, binding = 7, rgba32f) uniform image3D sum_g;
layout(set = 0, binding = 8, rgba32f) uniform image3D sum_b;
layout(push_constant) uniform PropagateParams {
  ivec4 cells_per_side;  // x
  vec4 damping;          // x: strength of the damping of negative flux (lpv_negative_damping)
} params_block;

void main() {
  const int n = params_block.cells_per_side.x;  // copied first: MRGI_UNIFORM_COPIES
  const float damping = params_block.damping.x;
  const ivec3 c = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(c, ivec3(n)))) return;
  const vec4 own_r = imageLoad(from_r, c), own_g = imageLoad(from_g, c), own_b = imageLoad(from_b, c);
  vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
#define LPV_LOAD_R(q) imageLoad(from_r, q)
#define LPV_LOAD_G(q) imageLoad(from_g, q)
#define LPV_LOAD_B(q) imageLoad(from_b, q)
#include "gi/lpv_gather.glsl"
  imageStore(to_r, c, r);
  imageStore(to_g, c, g);
  imageStore(to_b, c, b);
  imageStore(sum_r, c, imageLoad(sum_r, c) + r);
  imageStore(sum_g, c, imageLoad(sum_g, c) + g);
  imageStore(sum_b, c, imageLoad(sum_b, c) + b);
}
