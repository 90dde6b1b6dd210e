#version 460
// ssrt light estimation, step 2 of 2: sums the tiles' partial normal equations (light_reduce
// .comp) into one row of 192 floats that the host reads back a frame later and solves (Eigen,
// runtime/src/technique/ssrt/light_estimator.cpp). One workgroup; thread k owns entry k.
layout(local_size_x = 192) in;
layout(std430, set = 0, binding = 0) readonly buffer Partials { float partials[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Result { float result[]; };
layout(push_constant) uniform Push {
  ivec4 counts;  // x number of partials (light_reduce.comp invocations)
} pc;

void main() {
  int k = int(gl_LocalInvocationIndex);
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
