#version 450
// Resolve and every propagation step of a light propagation volume of at most 8^3 cells in one
// dispatch of one workgroup (gi/light_propagation.h: the reduced-volume levels): each invocation
// owns a cell, the previous step lives in shared memory, and the steps are separated by
// workgroup barriers instead of dispatches. On lavapipe a dispatch with its barrier costs about
// 1.6 ms of CPU at 8^3, far more than the step's arithmetic (8 steps: 13 CPU ms per frame,
// measured at dlpv's fast level); here the steps cost their arithmetic. Same gather as the
// one-step-a-dispatch path (gi/lpv_gather.glsl), same results to float rounding
// (tests/gi/test_lpv.cpp compares them).
#extension GL_GOOGLE_include_directive : require
#include "shared/lpv_math.h"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 8) in;
layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer cells;  // the injection's sums
layout(set = 0, binding = 1, rgba32f) uniform writeonly image3D sum_r;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image3D sum_g;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image3D sum_b;
layout(push_constant) uniform LocalParams {
  ivec4 sizes;   // x: cells per side used (<= 8), y: allocated, z: steps
  vec4 damping;  // x: strength of the damping of negative flux (lpv_negative_damping)
} params_block;

shared vec4 step_r[512], step_g[512], step_b[512];  // the previous step, 24 KiB

vec4 load4(int base) {
  return vec4(imageLoad(cells, base).x, imageLoad(cells, base + 1).x, imageLoad(cells, base + 2).x,
              imageLoad(cells, base + 3).x);
}

int slot(ivec3 q) { return (q.z * 8 + q.y) * 8 + q.x; }

void main() {
  const int n = params_block.sizes.x;  // copied first: MRGI_UNIFORM_COPIES
  const int allocated = params_block.sizes.y;
  const int steps = params_block.sizes.z;
  const float damping = params_block.damping.x;
  const ivec3 c = ivec3(gl_LocalInvocationID);
  const bool used = all(lessThan(c, ivec3(n)));
  vec4 own_r = vec4(0.0), own_g = vec4(0.0), own_b = vec4(0.0);
  if (used) {
    const int base = ((c.z * n + c.y) * n + c.x) * 12;
    own_r = load4(base);
    own_g = load4(base + 4);
    own_b = load4(base + 8);
  }
  vec4 sr_sum = own_r, sg_sum = own_g, sb_sum = own_b;
  step_r[slot(c)] = own_r;
  step_g[slot(c)] = own_g;
  step_b[slot(c)] = own_b;
  barrier();
#define LPV_LOAD_R(q) step_r[slot(q)]
#define LPV_LOAD_G(q) step_g[slot(q)]
#define LPV_LOAD_B(q) step_b[slot(q)]
  for (int s = 0; s < steps; ++s) {
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    if (used) {
#include "gi/lpv_gather.glsl"
    }
    barrier();  // every cell has read the previous step
    step_r[slot(c)] = r;
    step_g[slot(c)] = g;
    step_b[slot(c)] = b;
    own_r = r;
    own_g = g;
    own_b = b;
    sr_sum += r;
    sg_sum += g;
    sb_sum += b;
    barrier();  // the new step is complete
  }
  if (used) {
    imageStore(sum_r, c, sr_sum);
    imageStore(sum_g, c, sg_sum);
    imageStore(sum_b, c, sb_sum);
    // The layer past the used corner, finite for the trilinear lookup (lpv_resolve.comp says
    // why): written by the last used cells (the workgroup has no invocation there when n = 8),
    // each for the neighbours past it along the axes where it is last, and their combinations.
    if (n < allocated) {
      for (int bits = 1; bits < 8; ++bits) {
        const ivec3 step = ivec3(bits & 1, (bits >> 1) & 1, (bits >> 2) & 1);
        // Past the volume along an axis only from a cell that is last along it.
        const ivec3 last = ivec3(equal(c, ivec3(n - 1)));
        if (any(greaterThan(step, last))) continue;
        imageStore(sum_r, c + step, vec4(0.0));
        imageStore(sum_g, c + step, vec4(0.0));
        imageStore(sum_b, c + step, vec4(0.0));
      }
    }
  }
}
