#version 450
// The real scene's points into the real ISMs (gi/ism.h; DIR paper Sec. 4.3: a point cloud of the
// reconstruction, each point mapped to one VPL by its id). Point i belongs to VPL i mod n and
// reads the G-buffer at a Halton position of its own, so each VPL's map gets its own spread of the whole
// view (ism_point_u); it stands for the view's surface over the points per VPL (its pixel footprint at its
// depth times the pixels per point).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/vpl.glsl"
#include "gi/ism_common.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D real_position;  // xyz world, w depth (0 none)
layout(set = 0, binding = 2, r32ui) uniform uimage2D splat;
layout(set = 0, binding = 3, rgba16f) uniform readonly image2D real_normal;
layout(push_constant) uniform Params { IsmParams params; };
#include "gi/ism_splat.glsl"

void main() {
  int n = params.tiles.x;
  int i = int(gl_GlobalInvocationID.x);
  if (i >= n * params.tiles.w) return;
  ivec2 size = params.source.xy;
  ivec2 pixel = min(ivec2(ism_point_u(i / n, i % n) * vec2(size)), size - 1);
  vec4 p = imageLoad(real_position, pixel);
  if (!(p.w > 0.0f)) return;
  float footprint = p.w * p.w / (params.camera.x * params.camera.y);
  vec3 nrm = imageLoad(real_normal, pixel).xyz;
  float len = length(nrm);
  ism_splat(i % n, p.xyz, len > 0.0f ? nrm / len : vec3(0.0f), footprint * float(size.x * size.y) / float(params.tiles.w));
}
