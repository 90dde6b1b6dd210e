#version 460
// Traces the cones a buffer lists through dvct's four volumes (gi/vct_trace.glsl), for
// tests/gi/test_vct_trace.cpp: what dvct's shading reads, checked against scenes whose answer is
// known (a lit wall ahead, behind, beside; the wall as a virtual object in front of the scene).
#extension GL_GOOGLE_include_directive : require
#include "shared/vct_math.h"
#include "gi/vct_trace.glsl"

layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform sampler3D light_volume;
layout(set = 0, binding = 1) uniform sampler3D delta_volume;
layout(set = 0, binding = 2) uniform sampler3D scene_visibility;
layout(set = 0, binding = 3) uniform sampler3D object_visibility;
// Per cone, 4 vec4: origin + aperture, dir + max distance; out: light_with + trans_with,
// light_without + trans_without.
layout(std430, set = 0, binding = 4) buffer Cones { vec4 cones[]; };
layout(push_constant) uniform ProbeParams {
  vec4 volume;   // xyz origin (m), w voxel size (m)
  vec4 sizes;    // x cells, y max lod, z occlusion floor, w step scale
  ivec4 flags;   // x: VCT_LIGHT | VCT_WITHOUT
} params_block;

void main() {
  const vec4 volume = params_block.volume;  // copied first: MRGI_UNIFORM_COPIES
  const vec4 sizes = params_block.sizes;
  const int flags = params_block.flags.x;
  const uint i = gl_GlobalInvocationID.x;
  VctVolume v;
  v.origin = volume.xyz;
  v.voxel_size = volume.w;
  v.cells = sizes.x;
  v.texture_cells = sizes.x;
  v.max_lod = sizes.y;
  v.occlusion_floor = sizes.z;
  v.step_scale = sizes.w;
  const vec4 a = cones[4u * i], b = cones[4u * i + 1u];
  // No objects' own light volume here (the flag is masked off; delta_volume only fills the slot).
  const VctResult r = vct_trace_cone(light_volume, delta_volume, scene_visibility, object_visibility, delta_volume, v, a.xyz,
                                     normalize(b.xyz), a.w, b.w, flags & ~VCT_OBJECT_LIGHT);
  cones[4u * i + 2u] = vec4(r.light_with, r.trans_with);
  cones[4u * i + 3u] = vec4(r.light_without, r.trans_without);
}
