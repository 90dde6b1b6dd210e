#version 450
// Copy bandwidth (perf/peaks): each invocation copies one 16-byte element of a buffer far larger
// than the caches, in order (what a streaming pass can reach: bytes = 2 x size, read + write).
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Src { uvec4 src[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Dst { uvec4 dst[]; };
layout(push_constant) uniform Push { ivec4 counts; } pc;  // x elements

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (int(id) >= pc.counts.x) return;
  dst[id] = src[id];
}
