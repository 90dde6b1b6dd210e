#version 460
// An impostor texel (Popescu et al. 2006 as the caustics-DIR paper's Sec. 3.2 uses them): what a
// set's cube face sees from the set's centre, the surface data a reflected or refracted ray's hit
// needs (Sec. 5.1: the G-buffers of the hits are shaded like the primary one): world position,
// normal, albedo. Drawn with the reflective shadow maps' vertex shaders (gi/rsm_grid.vert for
// the reconstructed real scene, gi/rsm_mesh.vert for proxies and virtual objects), which hand on
// the same inputs as they give gi/rsm.frag.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(set = 0, binding = 4) uniform sampler2DArray base_color_maps;  // sRGB, decoded on fetch
layout(push_constant) uniform RsmDraw {
  mat4 view_proj;
  vec4 light;   // xyz: the set's centre
  vec4 colour;
  vec4 axis;
  ivec4 misc;   // y: material (-1: real); as gi/rsm.frag
} draw;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_albedo;
layout(location = 4) flat in vec4 in_material;  // x base-colour texture layer (-1 none)
layout(location = 0) out vec4 out_position;  // xyz world, w 1 real surface, 2 virtual (0: none)
layout(location = 1) out vec4 out_normal;    // xyz unit, facing the centre
layout(location = 2) out vec4 out_albedo;    // rgb linear

void main() {
  vec3 albedo = in_albedo.xyz;
  if (in_material.x >= 0.0f) albedo *= texture(base_color_maps, vec3(in_uv, in_material.x)).xyz;
  vec3 n = normalize(in_normal);
  if (any(isnan(n))) n = normalize(draw.light.xyz - in_world);
  if (dot(n, draw.light.xyz - in_world) < 0.0f) n = -n;  // two-sided: the side the centre sees
  out_position = vec4(in_world, draw.misc.y >= 0 ? 2.0f : 1.0f);
  out_normal = vec4(n, 0.0f);
  out_albedo = vec4(clamp(albedo, vec3(0.0f), vec3(1.0f)), 1.0f);
}
