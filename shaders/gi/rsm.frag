#version 460
// Reflective shadow map texel (Dachsbacher & Stamminger 2005; DLPV paper Sec. 4.3): world
// position, normal and the flux the texel's surface reflects. The light reaching the texel,
// per unit of the lamp's colour x intensity:
//   directional: E x the texel's area across the beam (orthographic map);
//   point / spot: I(w) x the texel's solid angle (at the map's centre, x cos^3 of the angle from
//     its axis), times the spot cone.
// Reflected flux = albedo x that x colour (a diffuse surface reflects albedo of what it gets;
// the cosine is in the texel's footprint on the surface, so it cancels); a glossy virtual
// surface's split into a diffuse part and a lobe is made from it when VPLs are drawn
// (gi/vpl_sample.comp), with the metallic and roughness written beside it.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(set = 0, binding = 4) uniform sampler2DArray base_color_maps;  // sRGB, decoded on fetch
layout(push_constant) uniform RsmDraw {
  mat4 view_proj;
  vec4 light;   // xyz: lamp position (w > 0: the texel's solid angle at the map's centre, sr) or
                // travel direction (w < 0: minus the texel's area across the beam, m^2)
  vec4 colour;  // rgb: colour x intensity; w: spot cos outer (-2: no cone)
  vec4 axis;    // xyz: the map's view axis; w: spot cos inner
  ivec4 misc;   // x: grid stride (G-buffer pixels between points); y: material (-1: proxy);
                // z: a proxy's hint colour, linear RGB8 packed; w: grid points per row
} draw;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_albedo;
layout(location = 4) flat in vec4 in_material;  // x base-colour texture layer (-1 none), y metallic,
                                                // z roughness (< 0: diffuse, no specular lobe)
layout(location = 0) out vec4 out_position;  // xyz world, w 1 real surface, virtual 2 + metallic / 2
layout(location = 1) out vec4 out_normal;    // xyz unit, facing the light; w roughness (< 0: diffuse)
layout(location = 2) out vec4 out_flux;      // rgb reflected W, a incident W per unit colour

void main() {
  vec3 albedo = in_albedo.xyz;
  if (in_material.x >= 0.0f) albedo *= texture(base_color_maps, vec3(in_uv, in_material.x)).xyz;
  vec3 n = normalize(in_normal);
  float incident;
  vec3 travel;
  if (draw.light.w > 0.0f) {
    travel = normalize(in_world - draw.light.xyz);
    float c = max(dot(travel, normalize(draw.axis.xyz)), 1e-3f);
    incident = draw.light.w * c * c * c;
    if (draw.colour.w > -1.5f) incident *= spot_falloff(dot(travel, normalize(draw.axis.xyz)), draw.colour.w, draw.axis.w);
  } else {
    travel = normalize(draw.light.xyz);
    incident = -draw.light.w;
  }
  if (dot(n, travel) > 0.0f) n = -n;  // two-sided: the side the light reaches
  // Virtual meshes carry a material: its metallic rides in w's fraction (readers test w > 1.5),
  // its roughness in the normal's w, for glossy VPLs (gi/vpl_sample.comp).
  out_position = vec4(in_world, draw.misc.y >= 0 ? 2.0f + 0.5f * clamp(in_material.y, 0.0f, 1.0f) : 1.0f);
  out_normal = vec4(n, in_material.z);
  out_flux = vec4(albedo * draw.colour.xyz * incident, incident);
}
