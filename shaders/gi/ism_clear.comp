#version 450
// Empties the used part of both ISM splat atlases (gi/ism.h) before the frame's points land.
#extension GL_GOOGLE_include_directive : require
#include "gi/ism_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) uniform writeonly uimage2D splat_real;
layout(set = 0, binding = 1, r32ui) uniform writeonly uimage2D splat_virtual;
layout(push_constant) uniform Params { ivec4 size; } params;  // x: the used atlas side

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  imageStore(splat_real, t, uvec4(MRGI_ISM_EMPTY));
  imageStore(splat_virtual, t, uvec4(MRGI_ISM_EMPTY));
}
