#version 450
// The ISMs as the lookups read them (gi/ism.h): level 0 of the distance atlas, per atlas (x real,
// y virtual), a texel's splatted distance, else its filled parent's in level 1 (pull-push),
// else MRGI_ISM_NONE (no surface in that direction: the light passes).
#extension GL_GOOGLE_include_directive : require
#include "gi/ism_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D splat_real;
layout(set = 0, binding = 1, r32ui) uniform readonly uimage2D splat_virtual;
layout(set = 0, binding = 2, rg32f) uniform readonly image2D filled;  // level 1, holes filled
layout(set = 0, binding = 3, rg32f) uniform writeonly image2D distances;  // level 0
layout(push_constant) uniform Params { ivec4 size; } params;  // x: the used atlas side

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  uint r = imageLoad(splat_real, t).x, v = imageLoad(splat_virtual, t).x;
  vec2 parent = imageLoad(filled, t / 2).xy;
  float dr = r != MRGI_ISM_EMPTY ? uintBitsToFloat(r) : (parent.x >= 0.0f ? parent.x : MRGI_ISM_NONE);
  float dv = v != MRGI_ISM_EMPTY ? uintBitsToFloat(v) : (parent.y >= 0.0f ? parent.y : MRGI_ISM_NONE);
  imageStore(distances, t, vec4(dr, dv, 0.0f, 0.0f));
}
