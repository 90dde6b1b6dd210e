#version 450
// Resolve and every propagation step of a light propagation volume of at most 8^3 cells in one
// dispatch of three workgroups, one per colour channel (gi/light_propagation.h: the
// reduced-volume levels): each invocation owns a cell, the previous step lives in shared memory,
// and the steps are separated by workgroup barriers instead of dispatches. On lavapipe a dispatch with its barrier costs about
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

shared vec4 step_c[512];  // this workgroup's channel, the previous step, 8 KiB

vec4 load4(int base) {
  return vec4(imageLoad(cells, base).x, imageLoad(cells, base + 1).x, imageLoad(cells, base + 2).x,
              imageLoad(cells, base + 3).x);
}

int slot(ivec3 q) { return (q.z * 8 + q.y) * 8 + q.x; }

void store_sum(int channel, ivec3 q, vec4 v) {
  if (channel == 0) imageStore(sum_r, q, v);
  else if (channel == 1) imageStore(sum_g, q, v);
  else imageStore(sum_b, q, v);
}

void main() {
  const int n = params_block.sizes.x;  // copied first: MRGI_UNIFORM_COPIES
  const int allocated = params_block.sizes.y;
  const int steps = params_block.sizes.z;
  const float damping = params_block.damping.x;
  // The colour channels propagate independently (the damping too is per channel): one
  // workgroup each, so lavapipe's threads share the work instead of one doing all of it.
  const int channel = int(gl_WorkGroupID.x);
  const ivec3 c = ivec3(gl_LocalInvocationID);
  const bool used = all(lessThan(c, ivec3(n)));
  vec4 own_r = vec4(0.0);
  if (used) own_r = load4(((c.z * n + c.y) * n + c.x) * 12 + channel * 4);
  vec4 sum = own_r;
  step_c[slot(c)] = own_r;
  barrier();
#define LPV_GATHER_ONE
#define LPV_LOAD_R(q) step_c[slot(q)]
  for (int s = 0; s < steps; ++s) {
    vec4 r = vec4(0.0);
    if (used) {
#include "gi/lpv_gather.glsl"
    }
    barrier();  // every cell has read the previous step
    step_c[slot(c)] = r;
    own_r = r;
    sum += r;
    barrier();  // the new step is complete
  }
  if (used) {
    store_sum(channel, c, sum);
    // The layer past the used corner, finite for the trilinear lookup (lpv_resolve.comp says
    // why): written by the last used cells (the workgroup has no invocation there when n = 8),
    // each for the neighbours past it along the axes where it is last, and their combinations.
    if (n < allocated) {
      for (int bits = 1; bits < 8; ++bits) {
        const ivec3 step = ivec3(bits & 1, (bits >> 1) & 1, (bits >> 2) & 1);
        // Past the volume along an axis only from a cell that is last along it.
        const ivec3 last = ivec3(equal(c, ivec3(n - 1)));
        if (any(greaterThan(step, last))) continue;
        store_sum(channel, c + step, vec4(0.0));
      }
    }
  }
}
