#version 450
// VPLs made elsewhere (the bounce light source, gi/vpl_bounce.h) into slots [first, first +
// count) of a VPL buffer (gi/vpl.h VplSampler::add_copy); the other slots keep what they hold.
#extension GL_GOOGLE_include_directive : require
#include "common/vpl.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Source { Vpl source[]; };
layout(std430, set = 0, binding = 1) buffer Vpls { Vpl vpls[]; };
layout(push_constant) uniform Params { ivec4 slots; } params;  // x: first slot; y: count

void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i < params.slots.y) vpls[params.slots.x + i] = source[i];
}
