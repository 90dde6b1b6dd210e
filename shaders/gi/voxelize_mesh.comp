#version 460
// Voxelisation of a triangle mesh (gi/voxelize.h, Voxelizer::add_mesh): one invocation a
// triangle of one draw range, world-space vertices in the scene's layout (frame/scene_gpu.h
// GpuVertex: position, normal, uv; 8 floats).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Vertices { float vertices[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 2, r32f) uniform imageBuffer cells;
layout(push_constant) uniform MeshParams {
  vec4 region;   // xyz: the volume's min corner (m); w: voxel size (m)
  ivec4 range;   // x: cells per side; y: first index; z: triangles; w: vertex offset
} params_block;

#include "gi/voxelize_splat.glsl"

vec3 vertex_position(uint v) { return vec3(vertices[8 * v + 0], vertices[8 * v + 1], vertices[8 * v + 2]); }
vec3 vertex_normal(uint v) { return vec3(vertices[8 * v + 3], vertices[8 * v + 4], vertices[8 * v + 5]); }

void main() {
  const vec4 region = params_block.region;  // copied first: MRGI_UNIFORM_COPIES
  const ivec4 range = params_block.range;
  const int t = int(gl_GlobalInvocationID.x);
  if (t >= range.z) return;
  const uint base = uint(range.y + 3 * t);
  const uint i0 = uint(int(indices[base + 0u]) + range.w);
  const uint i1 = uint(int(indices[base + 1u]) + range.w);
  const uint i2 = uint(int(indices[base + 2u]) + range.w);
  const vec3 oriented = vertex_normal(i0) + vertex_normal(i1) + vertex_normal(i2);
  splat_triangle(vertex_position(i0), vertex_position(i1), vertex_position(i2), oriented, region, range.x);
}
