#version 450
// Peak multiply-add throughput (perf/peaks): each invocation runs `iterations` rounds of eight
// independent vec4 multiply-adds (32 FMAs, 64 FLOPs per round), enough independent chains to
// hide the FMA latency. The factors come from push constants and the result is stored, so
// nothing folds away.
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) writeonly buffer Out { vec4 result[]; };
layout(push_constant) uniform Push {
  vec4 factors;   // x multiplier (< 1, keeps values finite), y addend
  ivec4 counts;   // x iterations, y invocations
} pc;

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (int(id) >= pc.counts.y) return;
  float s = float(id) * 1e-6f;
  vec4 a0 = vec4(s), a1 = a0 + 1.0f, a2 = a0 + 2.0f, a3 = a0 + 3.0f;
  vec4 a4 = a0 + 4.0f, a5 = a0 + 5.0f, a6 = a0 + 6.0f, a7 = a0 + 7.0f;
  vec4 m = vec4(pc.factors.x), c = vec4(pc.factors.y);
  for (int i = 0; i < pc.counts.x; ++i) {
    a0 = fma(a0, m, c); a1 = fma(a1, m, c); a2 = fma(a2, m, c); a3 = fma(a3, m, c);
    a4 = fma(a4, m, c); a5 = fma(a5, m, c); a6 = fma(a6, m, c); a7 = fma(a7, m, c);
  }
  result[id] = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7;
}
