#version 460
// Runs shared/mrgi_shared.h's integer helpers on the device, for tests/vulkan/
// test_shader_math.cpp: the CPU unit tests check the C++ compilation of the same functions,
// but a driver may lower the arithmetic differently (a division through a reciprocal would
// make div_nonneg's float quotient of an exact multiple fall short).
// Each invocation counts a hit on the element its spread workgroup id names (every element
// must be hit exactly once) and writes div_nonneg1 of its linear index by the push constant's
// divisor.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = 0) buffer Hits { uint hits[]; };      // width x height
layout(std430, set = 0, binding = 1) buffer Quotients { int quotients[]; };  // one per invocation
layout(push_constant) uniform Push {
  ivec4 size;  // x width, y height (invocations), z divisor
} pc;

void main() {
  ivec2 p = spread_invocation_id();
  if (p.x < pc.size.x && p.y < pc.size.y) atomicAdd(hits[p.y * pc.size.x + p.x], 1u);
  int row = int(gl_NumWorkGroups.x * gl_WorkGroupSize.x);
  int i = int(gl_GlobalInvocationID.y) * row + int(gl_GlobalInvocationID.x);
  quotients[i] = div_nonneg1(i, pc.size.z);
}
