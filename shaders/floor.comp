#version 450
// The floor pass: one load and one store per pixel, the least work a full-resolution pass can
// do. Its time is the unit every other pass is compared to (perf/). The write depends on the
// read so the load cannot be optimised away.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba8) uniform readonly image2D src_image;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D dst_image;
layout(push_constant) uniform FloorParams {
  ivec2 extent;  // used extent in pixels
} params;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= params.extent.x || p.y >= params.extent.y) return;
  vec4 c = imageLoad(src_image, p);
  imageStore(dst_image, p, vec4(1.0) - c);
}
