#version 450
// The floor pass's work through storage buffers (perf/peaks): per pixel of 640 x 480 one 4-byte
// load and one 4-byte store, 8 x 8 workgroups, in the floor pass's row-major pixel order. Beside
// the floor pass (the same through RGBA8 storage images) it gives what a pass pays for the image
// path itself on this driver.
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = 0) readonly buffer Src { uint src[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform Push { ivec4 counts; } pc;  // x width, y height

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.counts.x || p.y >= pc.counts.y) return;
  uint i = uint(p.y * pc.counts.x + p.x);
  dst[i] = ~src[i];
}
