#version 460
// Virtual G-buffer: world position + coverage, normal + roughness, linear base colour +
// metallic, emitted radiance. A virtual fragment behind the real surface seen at its pixel (the real geometry's
// depth, technique::RealGeometry) is hidden, so real objects occlude virtual ones.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "gbuffer/hidden_by_real.glsl"

layout(set = 0, binding = 2) uniform sampler2D real_position;         // xyz world, w depth
layout(set = 0, binding = 3) uniform sampler2DArray base_color_maps;  // sRGB, decoded on fetch
                                                                      // (emissive maps too)
layout(set = 0, binding = 4) uniform sampler2D real_normal;           // xyz world (coarse texels)
// Bindings 0 (frame constants), 1 (materials) and the push constants are read by virtual.vert,
// which says why, and arrive as the flat inputs below.
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in float in_view_z;
layout(location = 4) flat in vec4 in_base_color;
layout(location = 5) flat in vec4 in_material;  // x metallic, y roughness, z base-colour layer
layout(location = 6) flat in vec4 in_emission;
layout(location = 7) flat in vec4 in_k;
layout(location = 8) flat in vec4 in_camera;    // xyz camera centre (world), w behind-real tolerance
layout(location = 9) flat in mat3x4 in_to_camera;
layout(location = 12) flat in float in_coverage;  // 1, or 2 + material of a specular one
layout(location = 13) flat in vec2 in_real_scale; // real texels per pixel (x, y)
layout(location = 0) out vec4 out_position;  // xyz world, w coverage: 1, or 2 + the material index
                                             // of a reflective or refractive material (readers
                                             // test w > 0.5 for virtual, w > 1.5 for specular)
layout(location = 1) out vec4 out_normal;    // xyz unit, w roughness
layout(location = 2) out vec4 out_albedo;    // rgb linear base colour, w metallic
layout(location = 3) out vec4 out_emission;  // rgb emitted radiance (glTF emissive), w 0

void main() {
  if (hidden_by_real(real_position, real_normal, ivec2(gl_FragCoord.xy), in_k, in_to_camera, in_view_z,
                     in_real_scale, in_camera.w))
    discard;

  vec4 base = in_base_color;
  if (in_material.z >= 0.0f) base *= texture(base_color_maps, vec3(in_uv, in_material.z));
  vec3 n = normalize(in_normal);
  if (any(isnan(n))) n = vec3(0.0f, 1.0f, 0.0f);
  // A double-sided material seen from behind (single-sided ones are culled), or a flipped
  // normal: shade the side the camera sees.
  if (dot(n, in_camera.xyz - in_world) < 0.0f) n = -n;
  out_position = vec4(in_world, in_coverage);
  out_normal = vec4(n, clamp(in_material.y, 0.02f, 1.0f));
  out_albedo = vec4(clamp(base.rgb, vec3(0.0f), vec3(1.0f)), clamp(in_material.x, 0.0f, 1.0f));
  // Half floats end at 65504 (a material's emission is finite and non-negative on upload).
  vec3 emission = in_emission.rgb;
  if (in_emission.w >= 0.0f) emission *= texture(base_color_maps, vec3(in_uv, in_emission.w)).rgb;
  out_emission = vec4(min(emission, vec3(60000.0f)), 0.0f);
}
