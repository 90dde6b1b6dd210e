#version 460
// ssrt light estimation, step 2 of 2: sums the tiles' partial normal equations (light_reduce
// .comp) into one row of 192 floats that the host reads back a frame later and solves (Eigen,
// runtime/src/technique/ssrt/light_estimator.cpp). Invocation k owns entry k; 8 workgroups of
// 24 so a CPU device's worker threads share the sums (one workgroup of 192 ran on one thread:
// 8.5 ms at the full level's 9600 partials, with the other core idle).
layout(local_size_x = 24) in;
layout(std430, set = 0, binding = 0) readonly buffer Partials { float partials[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Result { float result[]; };
struct PushConstants {
  ivec4 counts;  // x number of partials (light_reduce.comp invocations)
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  pc = pc_block;  // MRGI_UNIFORM_COPIES
  int k = int(gl_GlobalInvocationID.x);
  // Kahan-compensated float sum: thousands of tiles stay accurate to float precision.
  float sum = 0.0f, comp = 0.0f;
  for (int g = 0; g < pc.counts.x; ++g) {
    float y = partials[g * 192 + k] - comp;
    float t = sum + y;
    comp = (t - sum) - y;
    sum = t;
  }
  result[k] = sum;
}
