#version 460
// Voxelisation of the real scene as the depth camera sees it (gi/voxelize.h,
// Voxelizer::add_depth_surface): the G-buffer's positions as a grid mesh, two triangles per
// 2 x 2 pixels, a triangle only where its three depths are one surface (mrgi_one_surface, the
// real caster mesh's rule), oriented by the G-buffer's normals.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D real_position;  // xyz world, w depth (0 invalid)
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D real_normal;    // xyz world, unit
layout(set = 0, binding = 2, r32f) uniform imageBuffer cells;
layout(push_constant) uniform DepthParams {
  vec4 region;   // xyz: the volume's min corner (m); w: voxel size (m)
  ivec4 sizes;   // x: cells per side; y, z: the G-buffer's used width and height; w: grid stride (px)
} params_block;

#include "gi/voxelize_splat.glsl"

void main() {
  const vec4 region = params_block.region;  // copied first: MRGI_UNIFORM_COPIES
  const ivec4 sizes = params_block.sizes;
  const int stride = max(sizes.w, 1);
  const ivec2 q = ivec2(gl_GlobalInvocationID.xy) * stride;
  if (q.x >= sizes.y - 1 || q.y >= sizes.z - 1) return;
  // The last column and row of grid points sit on the image's edge.
  const ivec2 q1 = min(q + ivec2(stride), ivec2(sizes.y, sizes.z) - 1);
  const vec4 p00 = imageLoad(real_position, q);
  const vec4 p10 = imageLoad(real_position, ivec2(q1.x, q.y));
  const vec4 p01 = imageLoad(real_position, ivec2(q.x, q1.y));
  const vec4 p11 = imageLoad(real_position, q1);
  const vec3 n = imageLoad(real_normal, q).xyz + imageLoad(real_normal, q1).xyz;
  if (mrgi_one_surface(p00.w, p10.w, p01.w)) splat_triangle(p00.xyz, p10.xyz, p01.xyz, n, region, sizes.x);
  if (mrgi_one_surface(p10.w, p11.w, p01.w)) splat_triangle(p10.xyz, p11.xyz, p01.xyz, n, region, sizes.x);
}
