// The virtual objects' vertex stage (the glTF objects, already in world space, seen by the
// colour camera), shared by the G-buffer (virtual.vert, at the internal resolution) and the
// output coverage (virtual_coverage.vert, MRGI_VIRTUAL_COVERAGE: at the output resolution, only
// what the occlusion test reads). Everything the fragment shader needs that is the same for the
// whole draw (the material, the real-geometry scale, the camera values of the occlusion test) is
// read here and handed on as flat varyings: lavapipe runs a fragment shader's every uniform or
// storage-buffer read as a per-lane gather (lp_bld_nir_soa.c: invocation 0 of a fragment may be
// inactive), 40 of them per fragment; a flat varying is one broadcast per triangle
// (frame_constants.glsl MRGI_UNIFORM_COPIES says more).
#include "common/frame_constants.glsl"
#include "common/scene_materials.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
// material: per draw (SceneGpu::draw, offset 0); real_texels_per_pixel: texels of real_position
// per raster pixel along x and y (recon/virtual_gbuffer.cpp, offset 8, once per pass).
layout(push_constant) uniform Draw { int material; vec2 real_texels_per_pixel; } draw;
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) out float out_view_z;
layout(location = 7) flat out vec4 out_k;           // the raster's intrinsics
layout(location = 8) flat out vec4 out_camera;      // xyz frame.camera_world, w frame.camera.z
layout(location = 9) flat out mat3x4 out_to_camera; // rows of frame.world_to_camera (x, y, z)
layout(location = 13) flat out vec2 out_real_scale; // real texels per raster pixel (x, y)
#ifndef MRGI_VIRTUAL_COVERAGE
layout(std430, set = 0, binding = 1) readonly buffer Materials { GpuMaterial materials[]; };
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 4) flat out vec4 out_base_color;  // GpuMaterial, as virtual.frag reads it
layout(location = 5) flat out vec4 out_material;    // GpuMaterial::params
layout(location = 6) flat out vec4 out_emission;
// The position's w (virtual.frag): 1, or 2 + the material's index for a reflective or refractive
// one (shared/specular_math.h specular_kind), which the specular stage reads its material from.
layout(location = 12) flat out float out_coverage;
#endif

void main() {
  out_view_z = (frame.world_to_camera * vec4(in_position, 1.0f)).z;
  // world_to_clip is the same at any raster size: the intrinsics scale with the image, pixel
  // centres included (Intrinsics::scaled_to), so NDC does not change.
  gl_Position = frame.world_to_clip * vec4(in_position, 1.0f);
  out_camera = vec4(frame.camera_world.xyz, frame.camera.z);
  out_to_camera = transpose(mat4x3(frame.world_to_camera));
  out_real_scale = draw.real_texels_per_pixel;
#ifdef MRGI_VIRTUAL_COVERAGE
  out_k = frame.output_k;
#else
  out_k = frame.internal_k;
  out_world = in_position;
  out_normal = in_normal;
  out_uv = in_uv;
  GpuMaterial m = materials[max(draw.material, 0)];
  out_base_color = m.base_color_factor;
  out_material = vec4(m.params.xyz, 0.0f);
  out_emission = m.emission;
  out_coverage = m.specular.x != 0.0f ? 2.0f + float(max(draw.material, 0)) : 1.0f;
#endif
}
