#version 450
// The virtual objects' points into the virtual ISMs (gi/ism.h): point i belongs to VPL i mod n
// and lies on a triangle of the meshes (full detail) picked uniformly by a Halton value
// (ism_point_u), at uniform barycentrics from the next coordinate and a third base; it stands for its triangle's area times the triangles
// per point (so a VPL's points cover the objects' area on average, wherever the triangles are
// small or large).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/vpl.glsl"
#include "gi/ism_common.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Vpls { Vpl vpls[]; };
layout(std430, set = 0, binding = 1) readonly buffer Vertices { float vertex_words[]; };  // technique::GpuVertex
layout(std430, set = 0, binding = 2) readonly buffer Indices { uint indices[]; };
// Per draw range: x first index, y triangles, z vertex offset, w triangles before it.
layout(std430, set = 0, binding = 3) readonly buffer Ranges { ivec4 ranges[]; };
layout(set = 0, binding = 4, r32ui) uniform uimage2D splat;
layout(push_constant) uniform Params { IsmParams params; };
#include "gi/ism_splat.glsl"

#include "gi/virtual_points.glsl"

void main() {
  int n = params.tiles.x;
  int i = int(gl_GlobalInvocationID.x);
  int triangles = params.source.x;
  if (i >= n * params.tiles.w || triangles <= 0) return;
  vec2 u = ism_point_u(i / n, i % n);
  float v3 = halton(uint(i / n) + 1u, 11u);  // the third coordinate: another base
  VirtualPoint p = virtual_point(vec3(u, v3), triangles, params.source.y);
  ism_splat(i % n, p.position, p.normal, p.area / float(params.tiles.w));
}
