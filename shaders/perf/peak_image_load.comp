#version 450
// Scattered image-load rate (perf/peaks): each invocation reads `loads` RGBA32F texels at hashed
// positions of a 640 x 480 image (the access pattern of a screen-space sampling pass such as the
// ssrt transfer, whose sample points land anywhere in the image) and stores their sum.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D source;
layout(std430, set = 0, binding = 1) writeonly buffer Out { vec4 result[]; };
layout(push_constant) uniform Push { ivec4 counts; } pc;  // x loads per invocation, y/z size

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
    // Within 64 px of the invocation's pixel, as a sampling radius on screen.
    ivec2 q = clamp(p + ivec2(int(h & 127u) - 64, int((h >> 7) & 127u) - 64), ivec2(0),
                    ivec2(pc.counts.y - 1, pc.counts.z - 1));
    sum += imageLoad(source, q);
  }
  result[seed] = sum;
}
