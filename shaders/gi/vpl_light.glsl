// What a VPL (common/vpl.glsl) gives a surface point, shared by the passes that gather VPL light
// (shaders/dir/shade_vpl.comp) and the bounce light source (gi/vpl_bounce.comp), so a point VPL
// and a directional one (an environment region) are read the same way everywhere. The including
// shader declares `ism_distances` (rg32f, level 0 of gi/ism.h's atlas: x real, y virtual) and
// the constant bool kGlossyLobes.
#ifndef MRGI_VPL_LIGHT_GLSL
#define MRGI_VPL_LIGHT_GLSL
#include "shared/vpl_math.h"
#include "common/vpl.glsl"
#include "gi/ism_common.glsl"

bool vpl_directional(Vpl v) { return (int(v.position.w) & MRGI_VPL_DIRECTIONAL) != 0; }

// Irradiance [W/m^2] (rgb) the VPL gives p (unit normal n), unoccluded: a point VPL's cosine
// emitter and, with kGlossyLobes and a lobe, its specular lobe (vpl_math.h vpl_irradiance_rgb,
// its 1 / d^2 clamped at `min_distance`); a directional one's irradiance times the cosine.
// kGlossyLobes: the including shader's specialisation (false: a lobe-free pipeline, whose
// VPLs carry none, compiles the lobe out; lavapipe runs every branch).
vec3 vpl_incident(Vpl v, vec3 p, vec3 n, float min_distance) {
  if (vpl_directional(v)) return v.flux.rgb * max(dot(n, v.normal.xyz), 0.0f);
  vec4 lobe = kGlossyLobes ? v.lobe : vec4(0.0f, 0.0f, 1.0f, -1.0f);
  return vpl_irradiance_rgb(p, n, v.position.xyz, v.normal.xyz, v.flux.rgb, lobe, v.specular, min_distance);
}

// Unit direction from p towards where the VPL's light comes from.
vec3 vpl_direction(Vpl v, vec3 p) {
  if (vpl_directional(v)) return v.normal.xyz;
  vec3 d = v.position.xyz - p;
  float l = length(d);
  return l > 0.0f ? d / l : v.normal.xyz;
}

// Whether p (unit normal n) is lit by VPL `slot` as its two imperfect shadow maps see it: x real
// casters, y virtual (1 lit, 0 shadowed). A point VPL's map (paraboloid) is read with a bias of
// `bias_relative` of the distance plus `bias_m`; a directional VPL's (orthographic) with `bias_m`
// plus the depth p's own surface spans over 1.5 texels at its slope to the light (tan of the
// angle, at most 8: a surface under a low sun changes depth fast across a texel). Directions outside a
// VPL's hemisphere are unlit (x = y = 0); points outside a directional map's square are lit (it
// covers where the virtual objects cast). `stored`: the two maps' texel (MRGI_ISM_NONE where none
// was read).
vec2 vpl_visibility(Vpl v, int slot, vec3 p, vec3 n, int side, int tiles_per_row, float bias_relative, float bias_m,
                    out vec2 stored) {
  ivec2 t;
  float dist, limit;
  stored = vec2(MRGI_ISM_NONE);
  if (vpl_directional(v)) {
    t = ism_ortho_texel(p, v.position.xyz, v.normal.xyz, v.normal.w, side, dist);
    if (t.x < 0) return vec2(1.0f);
    float c = clamp(abs(dot(n, v.normal.xyz)), 0.0f, 1.0f);
    float slope = min(sqrt(max(1.0f - c * c, 0.0f)) / max(c, 1e-3f), 8.0f);
    limit = dist - bias_m - 1.5f * (1.0f + slope) * 2.0f * v.normal.w / float(side);
  } else {
    vec3 d = p - v.position.xyz;
    dist = length(d);
    if (!(dist > 0.0f)) return vec2(0.0f);
    t = ism_texel(d / dist, v.normal.xyz, side);
    if (t.x < 0) return vec2(0.0f);
    limit = dist * (1.0f - bias_relative) - bias_m;
  }
  stored = imageLoad(ism_distances, ism_tile_origin(slot, tiles_per_row, side) + t).xy;
  return vec2(stored.x >= limit ? 1.0f : 0.0f, stored.y >= limit ? 1.0f : 0.0f);
}

#endif
