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
  // lpv_gather_from for each neighbour, its face loop spelled out with constant axes so that
  // every direction, SH basis and lobe is a constant (a loop over k and f kept them as run-time
  // work: 12 ms a step at 32^3 on lavapipe, against about 4 unrolled). A neighbour outside the
  // used volume reads as zero (no light from outside).
#define LPV_FACE(A, F) \
  r += lpv_gather_face(sr, own_r, A, F, damping); \
  g += lpv_gather_face(sg, own_g, A, F, damping); \
  b += lpv_gather_face(sb, own_b, A, F, damping);
#define LPV_NEIGHBOUR(A, F1, F2, F3, F4, F5) \
  { \
    const ivec3 q = c + ivec3(A); \
    const bool inside = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(n))); \
    const vec4 sr = inside ? imageLoad(from_r, q) : vec4(0.0); \
    const vec4 sg = inside ? imageLoad(from_g, q) : vec4(0.0); \
    const vec4 sb = inside ? imageLoad(from_b, q) : vec4(0.0); \
    LPV_FACE(A, F1) LPV_FACE(A, F2) LPV_FACE(A, F3) LPV_FACE(A, F4) LPV_FACE(A, F5) \
  }
  const vec3 px = vec3(1, 0, 0), nx = vec3(-1, 0, 0), py = vec3(0, 1, 0), ny = vec3(0, -1, 0);
  const vec3 pz = vec3(0, 0, 1), nz = vec3(0, 0, -1);
  LPV_NEIGHBOUR(px, nx, py, ny, pz, nz)
  LPV_NEIGHBOUR(nx, px, py, ny, pz, nz)
  LPV_NEIGHBOUR(py, px, nx, ny, pz, nz)
  LPV_NEIGHBOUR(ny, px, nx, py, pz, nz)
  LPV_NEIGHBOUR(pz, px, nx, py, ny, nz)
  LPV_NEIGHBOUR(nz, px, nx, py, ny, pz)
#undef LPV_NEIGHBOUR
#undef LPV_FACE
  imageStore(to_r, c, r);
  imageStore(to_g, c, g);
  imageStore(to_b, c, b);
  imageStore(sum_r, c, imageLoad(sum_r, c) + r);
  imageStore(sum_g, c, imageLoad(sum_g, c) + g);
  imageStore(sum_b, c, imageLoad(sum_b, c) + b);
}
