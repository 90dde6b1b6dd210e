#version 460
// The specular pixels of the trace's region (specular.cpp: the objects' projected boxes),
// listed by what the trace does there, for its three passes (trace.comp), list k from k x
// capacity on: 0 glass whose reflection is traced (its Fresnel factor at least the level's
// SpecularLevel::glass_reflection_fresnel), 1 mirrors, 2 glass whose reflection shows L_env;
// each pass then runs 64 listed pixels a workgroup, compiled without the paths it never takes.
// Over the region itself, lavapipe ran the whole trace (every path, lanes masked off) for each
// 8 x 8 block, specular or not, and a block with both kinds paid for both paths: ~1.3 of the
// trace's 3.3 ms on glass_mirror's fast dir frame went to pixels that traced nothing.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/scene_materials.glsl"
#include "common/frame_constants.glsl"
#include "specular/specular_params.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D virtual_position;  // w 2 + material: specular
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_normal;
layout(std140, set = 0, binding = 6) uniform FrameUbo { FrameConstants frame; };
layout(std140, set = 0, binding = 7) uniform SpecularUbo { SpecularConstants specular; };
layout(std430, set = 0, binding = 1) readonly buffer Materials { GpuMaterial materials[]; };
// VkDispatchIndirectCommand per list, x counted here (reset to 0, y and z 1).
layout(std430, set = 0, binding = 2) buffer TraceArgs { uvec4 args[3]; };
// Pixels listed per list (reset to 0).
layout(std430, set = 0, binding = 3) buffer TraceCounts { uint counts[4]; };
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
  GpuMaterial m = materials[int(v.w + 0.5f) - 2];
  uint k = 1u;
  if (int(m.specular.x + 0.5f) == SPECULAR_REFRACTIVE) {
    // trace.comp's Fresnel factor of the reflection off this glass pixel, from the same inputs.
    vec3 n = normalize(imageLoad(virtual_normal, pixel).xyz);
    vec3 view = normalize(v.xyz - frame.camera_world.xyz);
    if (dot(n, view) > 0.0f) n = -n;
    float f1 = fresnel_dielectric(max(-dot(view, n), 0.0f), 1.0f / max(m.specular.y, 1.0f));
    k = f1 >= specular.level.y ? 0u : 2u;
  }
  uint i = atomicAdd(counts[k], 1u);
  if (i >= uint(capacity.x)) return;  // never: a list holds every pixel
  if (i % 64u == 0u) atomicAdd(args[k].x, 1u);
  pixels[k * uint(capacity.x) + i] = uint(pixel.x) | (uint(pixel.y) << 16);
}
