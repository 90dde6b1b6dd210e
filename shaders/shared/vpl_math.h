// Virtual point lights and imperfect shadow maps (instant radiosity, Keller 1997; ISMs, Ritschel
// et al. 2008; as the DIR paper uses them, differential-instant-radiosity-reciprocal-shading.md
// Sec. 3), shared by the shaders (shaders/gi/vpl_*.comp, ism_*.comp, shaders/dir/) and the C++
// tests, under the rules of mrgi_shared.h.
//
// A VPL is a point on a diffuse surface (normal n) that reflects flux P: a cosine emitter of
// intensity I(w) = P / pi * max(0, n . w). A surface point p (normal n_p) at distance d along w
// from it receives the irradiance E = I(w) * max(0, n_p . -w) / d^2 (vpl_irradiance).
// Its shadow maps are paraboloid maps over the hemisphere around n (Brabec et al. 2002; ISMs use
// them for one map per VPL): direction w, in the VPL's tangent frame (t, b, n) as
// l = (w.t, w.b, w.n), maps to l.xy / (1 + l.z), the unit disk (paraboloid_uv); a map texel
// holds the distance from the VPL to the nearest surface in its direction.
#ifndef MRGI_VPL_MATH_H
#define MRGI_VPL_MATH_H

#include "shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

// The radical inverse of i in `base` (the Halton sequence's coordinate for that base), [0, 1).
// The paper draws its VPLs' RSM choice and position with Halton values (Sec. 3.7).
MRGI_FN float halton(uint i, uint base) {
  float f = 1.0f, r = 0.0f;
  float inv = 1.0f / float(base);
  while (i > 0u) {
    f *= inv;
    r += f * float(i % base);
    i /= base;
  }
  return min(r, 0.99999994f);
}

// An orthonormal tangent frame (t, b) for unit n, continuous except at n.z = -1 (Duff et al.,
// "Building an Orthonormal Basis, Revisited", 2017).
MRGI_FN vec3 frame_tangent(vec3 n) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float b = n.x * n.y * a;
  return vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
}
MRGI_FN vec3 frame_bitangent(vec3 n) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float b = n.x * n.y * a;
  return vec3(b, s + n.y * n.y * a, -n.y);
}

// Unit direction w (world) from a VPL of unit normal n -> paraboloid coordinates in the unit
// disk; z < 0 (behind the VPL's surface, where it emits nothing) -> outside, (2, 2).
MRGI_FN vec2 paraboloid_uv(vec3 w, vec3 n) {
  vec3 l = vec3(dot(w, frame_tangent(n)), dot(w, frame_bitangent(n)), dot(w, n));
  if (l.z < 0.0f) return vec2(2.0f);
  return vec2(l.x, l.y) / (1.0f + l.z);
}
// The inverse: a point of the unit disk -> the unit direction (world) it stands for.
MRGI_FN vec3 paraboloid_direction(vec2 uv, vec3 n) {
  float r2 = dot(uv, uv);
  vec3 l = vec3(2.0f * uv.x, 2.0f * uv.y, 1.0f - r2) / (1.0f + r2);
  return frame_tangent(n) * l.x + frame_bitangent(n) * l.y + n * l.z;
}
// Solid angle [sr] of the directions one texel of a paraboloid map of side `size` covers at
// disk point uv: the map's Jacobian, d omega = 4 / (1 + r^2)^2 du dv, times a texel's (2 / size)^2.
MRGI_FN float paraboloid_texel_solid_angle(vec2 uv, float size) {
  float k = 1.0f + dot(uv, uv);
  return 4.0f / (k * k) * (4.0f / (size * size));
}

// ---- glossy VPLs (the paper's "potentially glossy" D of LDDE paths, Sec. 3.1) ---------------
// A VPL on a surface with a specular lobe (a virtual material of the glTF metallic-roughness
// model) reflects the flux it received, Phi_in from unit direction `incident` (towards where the
// light came from), by the BRDF: its intensity towards w is Phi_in f_r(incident, w) (n . w).
// mrgi splits it into
//   - the diffuse part, a cosine emitter of flux = Phi_in base (1 - metallic) (1 - F0): brdf()'s
//     (1 - F) with F at normal incidence (F depends on w; the rest of it is at most F0's share);
//   - the specular part, Phi_in F D V (n . w) (mrgi_shared.h ggx_d_vis), F Schlick's from F0 =
//     mix(0.04, base, metallic): the VPL stores Phi_in F0 (rgb) and Phi_in's luminance for the
//     grazing term (Phi_in F = Phi_in F0 + (Phi_in - Phi_in F0) (1 - w.h)^5, Phi_in taken grey
//     there: only the tint of the grazing rise is lost).
// The lobe is at least MRGI_VPL_MIN_ROUGHNESS wide: a VPL stands for the light of its share of the
// maps (hundreds of texels), not for one point, and a narrower lobe turns it into a spot that the
// few dozen VPLs of a frame cannot average (a mirror's reflection is the specular stage's
// caustic maps).
#define MRGI_VPL_MIN_ROUGHNESS 0.3f

struct VplGlossySplit {
  vec3 diffuse_flux;   // W: the cosine emitter's reflected flux
  vec3 specular_flux;  // W: Phi_in F0
  float incident_luminance;  // W: luminance of Phi_in
};
MRGI_FN VplGlossySplit vpl_glossy_split(vec3 incident_flux, vec3 base, float metallic) {
  VplGlossySplit s;
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  s.diffuse_flux = incident_flux * base * (1.0f - metallic) * (vec3(1.0f) - f0);
  s.specular_flux = incident_flux * f0;
  s.incident_luminance = dot(incident_flux, vec3(0.2126f, 0.7152f, 0.0722f));
  return s;
}

// Intensity [W/sr] towards unit direction w of a VPL of unit normal nq: the cosine emitter of
// `flux` plus, where lobe.w >= 0, the specular lobe of roughness lobe.w (at least
// MRGI_VPL_MIN_ROUGHNESS) around the mirror direction of lobe.xyz (the unit incident direction),
// with specular = (Phi_in F0 rgb, Phi_in luminance) as vpl_glossy_split makes them.
MRGI_FN vec3 vpl_intensity(vec3 nq, vec3 w, vec3 flux, vec4 lobe, vec4 specular) {
  float c = max(dot(nq, w), 0.0f);
  vec3 i = flux * (c / MRGI_PI);
  if (lobe.w >= 0.0f && c > 0.0f && dot(nq, vec3(lobe)) > 0.0f) {
    vec3 l = vec3(lobe);
    vec3 f0_flux = vec3(specular);
    vec3 f = f0_flux + (vec3(specular.w) - f0_flux) * schlick_weight(dot(w, normalize(l + w)));
    i += f * (ggx_d_vis(nq, l, w, max(lobe.w, MRGI_VPL_MIN_ROUGHNESS)) * c);
  }
  return i;
}

// Irradiance [W/m^2] (rgb) at p (unit normal np) from a VPL at q (unit normal nq) as
// vpl_intensity describes it, unoccluded, its 1 / d^2 clamped at `min_distance` as
// vpl_irradiance's.
MRGI_FN vec3 vpl_irradiance_rgb(vec3 p, vec3 np, vec3 q, vec3 nq, vec3 flux, vec4 lobe, vec4 specular,
                                float min_distance) {
  vec3 v = p - q;
  float d2 = dot(v, v);
  if (!(d2 > 0.0f)) return vec3(0.0f);
  vec3 w = v / sqrt(d2);
  float receive = max(-dot(np, w), 0.0f);
  return vpl_intensity(nq, w, flux, lobe, specular) * (receive / max(d2, min_distance * min_distance));
}

// Irradiance [W/m^2] at p (unit normal np) from a VPL at q (unit normal nq, reflected flux
// `flux` W), unoccluded. The distance is clamped to `min_distance` [m]: the 1 / d^2 of a point
// light is unbounded next to it, where a VPL stands for light spread over its surroundings
// (every instant radiosity implementation bounds it; the paper does not state how).
MRGI_FN float vpl_irradiance(vec3 p, vec3 np, vec3 q, vec3 nq, float flux, float min_distance) {
  vec3 v = p - q;
  float d2 = dot(v, v);
  if (!(d2 > 0.0f)) return 0.0f;
  vec3 w = v / sqrt(d2);
  float emit = max(dot(nq, w), 0.0f);
  float receive = max(-dot(np, w), 0.0f);
  return flux / MRGI_PI * emit * receive / max(d2, min_distance * min_distance);
}

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef MRGI_FN
#endif

#endif  // MRGI_VPL_MATH_H
