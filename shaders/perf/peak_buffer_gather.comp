#version 450
// Scattered storage-buffer load rate (perf/peaks): peak_image_load.comp's access pattern (each
// invocation reads `loads` 16-byte texels at hashed positions within 64 px of its pixel of a
// 640 x 480 grid) from a buffer instead of an RGBA32F storage image. Beside image_load it says
// what a scattered read pays for the image path on this driver.
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = 0) readonly buffer Src { vec4 source[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Out { vec4 result[]; };
layout(push_constant) uniform Push { ivec4 counts; } pc;  // x loads per invocation, y/z size,
                                                          // w texels in `source`

uint hash(uint x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.counts.y || p.y >= pc.counts.z) return;
  uint seed = uint(p.y * pc.counts.y + p.x);
  vec4 sum = vec4(0.0f);
  for (int i = 0; i < pc.counts.x; ++i) {
    uint h = hash(seed * 16u + uint(i));
    ivec2 q = clamp(p + ivec2(int(h & 127u) - 64, int((h >> 7) & 127u) - 64), ivec2(0),
                    ivec2(pc.counts.y - 1, pc.counts.z - 1));
    sum += source[min(q.y * pc.counts.y + q.x, pc.counts.w - 1)];
  }
  result[seed] = sum;
}
