#version 460
// Traces the cones a buffer lists through a light and a visibility volume (gi/vct_trace.glsl),
// for tests/gi/test_vct_trace.cpp: what dvct's shading will read, checked against scenes whose
// answer is known (a lit wall ahead, behind, beside; a shadow cone through a slab).
#extension GL_GOOGLE_include_directive : require
#include "shared/vct_math.h"
#include "gi/vct_trace.glsl"

layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform sampler3D light_volume;
layout(set = 0, binding = 1) uniform sampler3D visibility_volume;
layout(std430, set = 0, binding = 2) buffer Cones { vec4 cones[]; };  // per cone: origin+aperture, dir+max distance; out: result
layout(push_constant) uniform ProbeParams {
  vec4 volume;   // xyz origin (m), w voxel size (m)
  vec4 sizes;    // x cells, y max lod, z occlusion floor
} params_block;

void main() {
  const vec4 volume = params_block.volume;  // copied first: MRGI_UNIFORM_COPIES
  const vec4 sizes = params_block.sizes;
  const uint i = gl_GlobalInvocationID.x;
  VctVolume v;
  v.origin = volume.xyz;
  v.voxel_size = volume.w;
  v.cells = sizes.x;
  v.max_lod = sizes.y;
  v.occlusion_floor = sizes.z;
  const vec4 a = cones[3u * i], b = cones[3u * i + 1u];
  cones[3u * i + 2u] = vct_trace(light_volume, visibility_volume, v, a.xyz, normalize(b.xyz), a.w, b.w);
}
