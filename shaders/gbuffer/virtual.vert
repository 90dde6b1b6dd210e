#version 460
// Virtual G-buffer: the glTF objects (already in world space) seen by the colour camera.
// Everything the fragment shader needs that is the same for the whole draw (the material, the
// real-geometry step, the camera values of the occlusion test) is read here and handed on as
// flat varyings: lavapipe runs a fragment shader's every uniform or storage-buffer read as a
// per-lane gather (lp_bld_nir_soa.c: invocation 0 of a fragment may be inactive), 40 of them
// per fragment; a flat varying is one broadcast per triangle (frame_constants.glsl
// MRGI_UNIFORM_COPIES says more).
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"
#include "common/scene_materials.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(std430, set = 0, binding = 1) readonly buffer Materials { GpuMaterial materials[]; };
// material: per draw; real_step: internal pixels per texel side of real_position.
layout(push_constant) uniform Draw { int material; int real_step; } draw;
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out float out_view_z;
layout(location = 4) flat out vec4 out_base_color;  // GpuMaterial, as virtual.frag reads it
layout(location = 5) flat out vec4 out_material;    // GpuMaterial::params, w: real_step
layout(location = 6) flat out vec4 out_emission;
layout(location = 7) flat out vec4 out_k;           // frame.internal_k
layout(location = 8) flat out vec4 out_camera;      // xyz frame.camera_world, w frame.camera.z
layout(location = 9) flat out mat3x4 out_to_camera; // rows of frame.world_to_camera (x, y, z)
// The position's w (virtual.frag): 1, or 2 + the material's index for a reflective or refractive
// one (shared/specular_math.h specular_kind), which the specular stage reads its material from.
layout(location = 12) flat out float out_coverage;

void main() {
  out_world = in_position;
  out_normal = in_normal;
  out_uv = in_uv;
  out_view_z = (frame.world_to_camera * vec4(in_position, 1.0f)).z;
  gl_Position = frame.world_to_clip * vec4(in_position, 1.0f);
  GpuMaterial m = materials[max(draw.material, 0)];
  out_base_color = m.base_color_factor;
  out_material = vec4(m.params.xyz, float(max(draw.real_step, 1)));
  out_emission = m.emission;
  out_coverage = m.specular.x != 0.0f ? 2.0f + float(max(draw.material, 0)) : 1.0f;
  out_k = frame.internal_k;
  out_camera = vec4(frame.camera_world.xyz, frame.camera.z);
  out_to_camera = transpose(mat4x3(frame.world_to_camera));
}
