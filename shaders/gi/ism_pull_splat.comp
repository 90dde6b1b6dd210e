#version 450
// Pull-push hole filling of the ISMs (gi/ism.h; Ritschel et al. 2008 Sec. 4, Marroquim et al.
// 2007), pull from the splats: each texel of level 1 the mean of its four children's distances
// that a point reached, per atlas (x real, y virtual), where at least MRGI_ISM_PULL_MIN_CHILDREN
// did; else -1. Tiles are a power of
// two wide, so a texel's children never cross into another VPL's tile.
#extension GL_GOOGLE_include_directive : require
#include "gi/ism_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D splat_real;
layout(set = 0, binding = 1, r32ui) uniform readonly uimage2D splat_virtual;
layout(set = 0, binding = 2, rg32f) uniform writeonly image2D coarser;
layout(push_constant) uniform Params { ivec4 size; } params;  // x: the coarser level's used side

vec2 child(ivec2 c) {
  uint r = imageLoad(splat_real, c).x, v = imageLoad(splat_virtual, c).x;
  return vec2(r == MRGI_ISM_EMPTY ? -1.0f : uintBitsToFloat(r), v == MRGI_ISM_EMPTY ? -1.0f : uintBitsToFloat(v));
}

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  vec2 sum = vec2(0.0f), count = vec2(0.0f);
  for (int k = 0; k < 4; ++k) {
    vec2 d = child(t * 2 + ivec2(k & 1, k >> 1));
    vec2 valid = vec2(greaterThanEqual(d, vec2(0.0f)));
    sum += d * valid;
    count += valid;
  }
  imageStore(coarser, t, vec4(mix(vec2(-1.0f), sum / max(count, vec2(1.0f)), greaterThanEqual(count, vec2(MRGI_ISM_PULL_MIN_CHILDREN))), 0.0f, 0.0f));
}
