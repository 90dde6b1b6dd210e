#version 460
// The specular pixels of the trace's region (specular.cpp: the objects' projected boxes),
// listed by kind for the trace's two passes (trace.comp): glass pixels from the list's start,
// mirror pixels from `capacity` on; each pass then runs 64 listed pixels a workgroup. Over the
// region itself, lavapipe ran the whole trace (every path, lanes masked off) for each 8 x 8
// block, specular or not, and a block with both kinds paid for both paths: ~1.3 of the trace's
// 3.3 ms on glass_mirror's fast dir frame went to pixels that traced nothing.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/scene_materials.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D virtual_position;  // w 2 + material: specular
layout(std430, set = 0, binding = 1) readonly buffer Materials { GpuMaterial materials[]; };
// VkDispatchIndirectCommand per kind (glass, mirrors), x counted here (reset to 0, y and z 1).
layout(std430, set = 0, binding = 2) buffer TraceArgs { uvec4 args[2]; };
// Pixels listed per kind (reset to 0).
layout(std430, set = 0, binding = 3) buffer TraceCounts { uint counts[2]; };
layout(std430, set = 0, binding = 4) writeonly buffer TracePixels { uint pixels[]; };  // x | y << 16
layout(push_constant) uniform List {
  ivec4 region;    // xy first pixel, zw size
  ivec4 capacity;  // x pixels each kind's list holds
};

void main() {
  ivec2 pixel = region.xy + ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(ivec2(gl_GlobalInvocationID.xy), region.zw))) return;
  vec4 v = imageLoad(virtual_position, pixel);
  if (!(v.w > 1.5f)) return;
  int kind = int(materials[int(v.w + 0.5f) - 2].specular.x + 0.5f);
  uint k = kind == SPECULAR_REFRACTIVE ? 0u : 1u;
  uint i = atomicAdd(counts[k], 1u);
  if (i >= uint(capacity.x)) return;  // never: a list holds every pixel
  if (i % 64u == 0u) atomicAdd(args[k].x, 1u);
  pixels[k * uint(capacity.x) + i] = uint(pixel.x) | (uint(pixel.y) << 16);
}
