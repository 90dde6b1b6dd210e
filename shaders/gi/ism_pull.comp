#version 450
// Pull-push of the ISMs (gi/ism.h), a further pull: level m from level m - 1, each texel the mean
// of its valid children (>= 0) where at least MRGI_ISM_PULL_MIN_CHILDREN are, else -1.
#extension GL_GOOGLE_include_directive : require
#include "gi/ism_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rg32f) uniform readonly image2D finer;
layout(set = 0, binding = 1, rg32f) uniform writeonly image2D coarser;
layout(push_constant) uniform Params { ivec4 size; } params;  // x: the coarser level's used side

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  vec2 sum = vec2(0.0f), count = vec2(0.0f);
  for (int k = 0; k < 4; ++k) {
    vec2 d = imageLoad(finer, t * 2 + ivec2(k & 1, k >> 1)).xy;
    vec2 valid = vec2(greaterThanEqual(d, vec2(0.0f)));
    sum += d * valid;
    count += valid;
  }
  imageStore(coarser, t, vec4(mix(vec2(-1.0f), sum / max(count, vec2(1.0f)), greaterThanEqual(count, vec2(MRGI_ISM_PULL_MIN_CHILDREN))), 0.0f, 0.0f));
}
