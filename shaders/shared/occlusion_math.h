// Environment occlusion by sphere proxies, shared by the shader (shaders/shading/
// environment_occlusion.comp) and the C++ tests, under the rules of mrgi_shared.h.
//
// A virtual object stands between a real surface point and part of the environment: the point
// loses the radiance the object hides, weighted by the cosine to its normal. With the object
// approximated by spheres (frame/occluder_spheres.h), each sphere hides a cap of the sky:
//   - sphere_form_factor: the cap's cosine-weighted solid angle over pi (the fraction of a
//     uniform sky's irradiance it blocks), exact also where the sphere crosses the point's
//     horizon (the form factor of a sphere seen from a differential area, J. Snyder, "Area
//     light sources for real-time graphics", 1996; the horizon-crossing case as written up by
//     Lagarde & de Rousiers, "Moving Frostbite to PBR", 2014, eq. 18);
//   - sh_cap_band_factors: the mean of an SH band over a cap, as a factor of the band's value
//     at the cap's centre (Funk-Hecke with the cap's indicator as kernel), so the mean radiance
//     the cap hides is one evaluation of the environment's SH with per-band factors
//     (sh_cap_mean_radiance), not an integral per pixel.
//   - cap_overlap_solid_angle: the solid angle two caps share (exact), so a bright, broad part
//     of the environment (a low sun behind haze, a window) kept apart from the SH as a cone is
//     hidden by the part of it a sphere's cap covers: its shadow falls in its direction, which
//     an SH of 4 bands blurs over the whole hemisphere.
// Several spheres combine as independent occluders: the blocked fraction is 1 - prod(1 - f_i)
// (overlapping spheres of one object would count their shared part twice if summed), and the
// blocked radiance is the f-weighted mean of their caps' radiance (sphere_occlusion_add /
// sphere_occlusion_irradiance).
//
// Near field: what a sphere hides is the environment only where nothing real lies beyond it. A
// wall of a room corner looks through the object at the floor or the other wall, whose radiance
// (what the camera sees there) is what the object takes from it, not the sky's; and a bright
// region beyond a real surface was never reaching the point (the camera already shows that
// shadow). The pass marches each sphere's ray from past its far side (near_field_march_t)
// through the real G-buffer, and where it crosses a real surface that surface's radiance is the
// sphere's cap radiance and the sphere hides none of the regions.
#ifndef MRGI_OCCLUSION_MATH_H
#define MRGI_OCCLUSION_MATH_H

#include "shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
using glm::ivec4;
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

// Fraction (0..1) of the cosine-weighted hemisphere above a point with unit normal n that a
// sphere covers: cos_theta = dot(n, direction to the sphere's centre), sin_alpha_sq =
// (radius / distance)^2 (< 1: the point is outside the sphere). Fully above the horizon it is
// sin^2(alpha) cos(theta); fully below, 0.
MRGI_FN float sphere_form_factor(float cos_theta, float sin_alpha_sq) {
  float s2 = clamp(sin_alpha_sq, 1e-8f, 0.9999f);
  float c = clamp(cos_theta, -1.0f, 1.0f);
  if (c * c >= s2) return c > 0.0f ? s2 * c : 0.0f;
  // The cap crosses the horizon: the part above it.
  float sin_theta = sqrt(max(1.0f - c * c, 1e-12f));
  float x = sqrt(1.0f / s2 - 1.0f);  // cot(alpha)
  float y = clamp(-x * c / sin_theta, -1.0f, 1.0f);
  float s = sin_theta * sqrt(max(1.0f - y * y, 0.0f));
  float e = (c * acos(y) - x * s) * s2 + atan(s / x);
  return clamp(e / MRGI_PI, 0.0f, 1.0f);
}

// Per band l = 0..3: the mean over a cap of half-angle alpha (cos_alpha) of a band-l function,
// over its value at the cap's centre: (2 pi / solid angle) * integral_{cos_alpha}^1 P_l(t) dt.
// 1 for every band as the cap shrinks to a point; (1, 1/2, 0, -1/8) for a hemisphere.
MRGI_FN vec4 sh_cap_band_factors(float cos_alpha) {
  float c = clamp(cos_alpha, -1.0f, 1.0f);
  // The integrals of P1, P2, P3 from c to 1 are (1 - c^2) / 2, (c - c^3) / 2 and
  // (5 c^2 - 1)(1 - c^2) / 8; each has the factor (1 - c), which the solid angle 2 pi (1 - c)
  // divides out exactly (no 0 / 0 as the cap shrinks).
  return vec4(1.0f, 0.5f * (1.0f + c), 0.5f * c * (1.0f + c), (5.0f * c * c - 1.0f) * (1.0f + c) * 0.125f);
}

// Mean radiance of a radiance SH (one SH16 a colour channel, bands 0..3) over the cap around
// unit `direction` with half-angle cos_alpha, clamped at 0 (SH ringing).
MRGI_FN vec3 sh_cap_mean_radiance(SH16 r, SH16 g, SH16 b, vec3 direction, float cos_alpha) {
  vec4 f = sh_cap_band_factors(cos_alpha);
  SH16 y = sh_basis16(direction);
  y.c0 = y.c0 * vec4(f.x, f.y, f.y, f.y);
  y.c1 = y.c1 * vec4(f.z, f.z, f.z, f.z);
  y.c2 = y.c2 * vec4(f.z, f.w, f.w, f.w);
  y.c3 = y.c3 * f.w;
  return max(vec3(sh_dot(r, y), sh_dot(g, y), sh_dot(b, y)), vec3(0.0f));
}

// Irradiance at unit normal n from a radiance SH16 per channel (bands 0..2; band 3 of the
// clamped cosine is 0), clamped at 0.
MRGI_FN vec3 sh_irradiance16(SH16 r, SH16 g, SH16 b, vec3 n) {
  SH16 y = sh_scale_cosine_lobe(sh_basis16(n));
  return max(vec3(sh_dot(r, y), sh_dot(g, y), sh_dot(b, y)), vec3(0.0f));
}

// A diffuse sphere lit by a directional light (irradiance E at normal incidence, from unit
// direction l) shows a viewer in direction v (unit, from the sphere) the mean radiance
// albedo E / pi x lambert_sphere_phase(dot(l, v)) over its visible disk: the Lambert sphere's
// phase function, (2 / 3 pi) (sin a + (pi - a) cos a), 2/3 face-on (limb darkening), 0 from
// behind, 2 / 3 pi side-on, where a flat plate facing the viewer would show nothing (the limit
// the oriented patches below are tested against).
MRGI_FN float lambert_sphere_phase(float cos_a) {
  float c = clamp(cos_a, -1.0f, 1.0f);
  float a = acos(c);
  return (2.0f / (3.0f * MRGI_PI)) * (sqrt(max(1.0f - c * c, 0.0f)) + (MRGI_PI - a) * c);
}
// What a lit virtual object sends a viewer in unit direction v, from its surface gathered into
// oriented patches (frame/surface_orientation.h; convex: no patch shades another): each patch's
// radiance weighted by its projected area towards v. lit_patch_term is one patch's part,
// vec4(radiance x w, w) with w = area x max(dot(n, v), 0); the object's radiance is the sum's
// rgb over its w (lit_object_radiance). For a sphere's many patches under a directional light it
// tends to albedo E / pi x lambert_sphere_phase; a box lit from above shows a viewer beside it
// its unlit sides.
MRGI_FN vec4 lit_patch_term(vec4 normal_area, vec3 radiance, vec3 v) {
  float w = normal_area.w * max(dot(vec3(normal_area.x, normal_area.y, normal_area.z), v), 0.0f);
  return vec4(radiance * w, w);
}
MRGI_FN vec3 lit_object_radiance(vec4 sum) {
  return sum.w > 1e-12f ? vec3(sum.x, sum.y, sum.z) / sum.w : vec3(0.0f);
}

// Solid angle (sr) shared by two caps on the unit sphere with half-angles a and b (0..pi/2),
// given by their cosines and sines, whose centres' directions have dot product x. The lune of
// two small circles: 2 [pi - acos((x - cos a cos b) / (sin a sin b))
//                         - cos a acos((cos b - x cos a) / (sin theta sin a))
//                         - cos b acos((cos a - x cos b) / (sin theta sin b))];
// the smaller cap's whole solid angle when it lies inside the other, 0 when they are apart
// (both decided without a trigonometric call: cos(a + b) and cos(a - b) from the cosines and
// sines, which is what keeps the per-pixel pass cheap).
MRGI_FN float cap_overlap_solid_angle_cs(float x, float ca, float sa, float cb, float sb) {
  if (sa <= 0.0f || sb <= 0.0f) return 0.0f;
  if (x <= ca * cb - sa * sb) return 0.0f;  // theta >= a + b
  float c_lo = max(ca, cb);
  if (x >= ca * cb + sa * sb) return 2.0f * MRGI_PI * (1.0f - c_lo);  // theta <= |a - b|
  float st = sqrt(max(1.0f - x * x, 1e-12f));
  if (sa + sb < 0.2f) {
    // Small caps: the lens of two discs in the tangent plane (relative error about (a + b)^2 / 8,
    // where the spherical form loses its digits to cos ~ 1 in single precision).
    float a = asin(sa), b = asin(sb), d = max(atan(st, x), 1e-9f);
    float u = clamp((d * d + a * a - b * b) / (2.0f * d * a), -1.0f, 1.0f);
    float v = clamp((d * d + b * b - a * a) / (2.0f * d * b), -1.0f, 1.0f);
    float k = max((-d + a + b) * (d + a - b) * (d - a + b) * (d + a + b), 0.0f);
    return clamp(a * a * acos(u) + b * b * acos(v) - 0.5f * sqrt(k), 0.0f, 2.0f * MRGI_PI * (1.0f - c_lo));
  }
  float t0 = acos(clamp((x - ca * cb) / max(sa * sb, 1e-12f), -1.0f, 1.0f));
  float t1 = acos(clamp((cb - x * ca) / max(st * sa, 1e-12f), -1.0f, 1.0f));
  float t2 = acos(clamp((ca - x * cb) / max(st * sb, 1e-12f), -1.0f, 1.0f));
  return clamp(2.0f * (MRGI_PI - t0 - ca * t1 - cb * t2), 0.0f, 2.0f * MRGI_PI * (1.0f - c_lo));
}

// The fraction (0..1) of cap b that cap a covers, from the angles (radians; a, b in 0..pi/2,
// theta = the angle between their centres): exact where they are apart or one holds the other,
// linear in theta between (within 0.11 of cap b's solid angle of the exact overlap, 0.02 on
// average over half-angles 1-80 degrees: tested), with one inverse trigonometric call a pair
// where the exact lune needs three.
// `vers_a`, `vers_b`: 1 - cos of each half-angle (the caller has them without a trigonometric call).
MRGI_FN float cap_covered_fraction_v(float theta, float a, float b, float vers_a, float vers_b) {
  float lo = min(a, b);
  if (lo <= 0.0f) return 0.0f;
  float t = clamp((a + b - theta) / (2.0f * lo), 0.0f, 1.0f);
  // The smaller cap's solid angle over cap b's: 1 when b is the smaller.
  float ratio = a < b ? vers_a / max(vers_b, 1e-12f) : 1.0f;
  return t * ratio;
}
MRGI_FN float cap_covered_fraction(float theta, float a, float b) {
  return cap_covered_fraction_v(theta, a, b, 1.0f - cos(a), 1.0f - cos(b));
}

// The same from the angles: centres `theta` apart (0..pi), half-angles a and b (radians).
MRGI_FN float cap_overlap_solid_angle(float theta, float a, float b) {
  return cap_overlap_solid_angle_cs(cos(theta), cos(a), sin(a), cos(b), sin(b));
}

// Accumulated occlusion of a point: product of the unblocked fractions, and the sum of f_i and
// of f_i times cap radiance_i.
struct SphereOcclusion {
  float open;           // prod (1 - f_i)
  float weight;         // sum f_i
  vec3 weighted;        // sum f_i * mean cap radiance_i
};
MRGI_FN SphereOcclusion sphere_occlusion_none() {
  SphereOcclusion o;
  o.open = 1.0f;
  o.weight = 0.0f;
  o.weighted = vec3(0.0f);
  return o;
}
MRGI_FN SphereOcclusion sphere_occlusion_add(SphereOcclusion o, float fraction, vec3 radiance) {
  o.open *= 1.0f - fraction;
  o.weight += fraction;
  o.weighted += radiance * fraction;
  return o;
}
// Near field: the distance along a sphere's direction of march step k (0..steps-1), from its far
// side (`start`, metres from the point) out to `reach`: denser near the object, where the
// surfaces that matter most lie; nowhere past the far side when the reach is inside it.
MRGI_FN float near_field_march_t(float start, float reach, int k, int steps) {
  float u = float(k + 1) / float(max(steps, 1));
  return start + max(reach - start, 0.0f) * u * u;
}
// The irradiance (W/m^2 per channel) the spheres hide from the point: pi x the blocked fraction
// x the fraction-weighted mean radiance of their caps.
MRGI_FN vec3 sphere_occlusion_irradiance(SphereOcclusion o) {
  if (!(o.weight > 1e-8f)) return vec3(0.0f);
  return o.weighted * (MRGI_PI * (1.0f - o.open) / o.weight);
}

// An object's proxies against its silhouette. Spheres fitted inside a solid overlap, and seen
// from afar their caps lie over one another: the independent-occluder sum of a box's or a
// duck's 16 proxies is 1.3-2x the form factor of the mesh itself beyond a few radii (ray-cast
// against the triangles; at 1.3 radii it is 0.9-1.6x, the spheres' own 1 - prod(1 - f) saturating).
// Far off, an object hides its silhouette area A(w) seen along w (silhouette_area_term summed
// over its oriented patches: half of each patch's facing area x |dot(n, w)|, exact for a convex
// mesh with flat patches), the spheres sum(pi r^2): each sphere's fraction is scaled by
// far_field_scale, their ratio (at most 4) taken in full beyond 4 bounding radii, not at all
// within 1.5 (the proxies' own near-field estimate), linearly between.
MRGI_FN float silhouette_area_term(vec4 normal_facing, vec3 w) {
  return 0.5f * normal_facing.w * abs(dot(vec3(normal_facing.x, normal_facing.y, normal_facing.z), w));
}
MRGI_FN float far_field_scale(float silhouette_m2, float disc_area_m2, float distance_over_radius) {
  if (!(disc_area_m2 > 0.0f) || !(silhouette_m2 > 0.0f)) return 1.0f;
  float t = clamp((distance_over_radius - 1.5f) / 2.5f, 0.0f, 1.0f);
  return mix(1.0f, min(silhouette_m2 / disc_area_m2, 4.0f), t);
}

// The real surfaces round an object, darkened by it, reflect less light on to the rest of the
// scene (the second bounce of the occlusion): the object takes `flux` (W per channel) that they
// would have reflected. It is lost as from a diffuse emitter lying on the ground at the object's
// base (facing up, world +y), spread over `spread` metres (the shadow's reach: the distance
// is softened by it, so the base's neighbourhood does not see an infinite peak). The
// irradiance (W/m^2) a real point p with unit normal n loses:
//   flux x max(cos at the emitter, 0) x max(cos at p, 0) / (pi (d^2 + spread^2)).
MRGI_FN vec3 real_bounce_loss(vec3 flux, vec3 base, float spread, vec3 p, vec3 n) {
  vec3 d = p - base;
  float d2 = dot(d, d);
  float inv_d = 1.0f / sqrt(max(d2, 1e-8f));
  float cos_e = max(d.y * inv_d, 0.0f);
  float cos_p = max(-dot(n, d) * inv_d, 0.0f);
  return flux * (cos_e * cos_p / (MRGI_PI * (d2 + spread * spread)));
}

// The environment-occlusion pass's uniform block (shading/environment_occlusion.h), std140.
#define MRGI_MAX_OCCLUDER_SPHERES 64
#define MRGI_MAX_OCCLUSION_REGIONS 4
#define MRGI_MAX_OCCLUSION_OBJECTS 8
#define MRGI_OBJECT_PATCHES 8
struct EnvOcclusionSet {
  ivec4 count;                                   // x spheres; y divisor (internal pixels a texel side);
                                                 // z regions (below); w near-field march steps (0 = off)
  vec4 near_field;                               // x how far the march reaches (metres); y 1 where
                                                 // the objects' lit radiance (below) is added; z the
                                                 // objects (below); w 1 where their real bounce
                                                 // loss (object_loss) is taken
  vec4 radiance[12];                             // radiance SH16 of the occludable light: r c0..c3, g, b
                                                 // (without the regions below)
  vec4 spheres[MRGI_MAX_OCCLUDER_SPHERES];       // world xyz centre, w radius (metres)
  vec4 albedo[MRGI_MAX_OCCLUDER_SPHERES];        // rgb the sphere's object's mean diffuse albedo; w
                                                 // its object among the lit ones below (-1 none)
  // count.z broad regions kept apart from `radiance` (cap_covered_fraction): xyz the unit
  // direction towards the region, w 1 - the cosine of its cone's half-angle; rgb its irradiance
  // at normal incidence (W/m^2), w the half-angle (radians).
  vec4 regions[MRGI_MAX_OCCLUSION_REGIONS];
  vec4 region_irradiance[MRGI_MAX_OCCLUSION_REGIONS];
  // The objects (near_field.z of them, at most MRGI_MAX_OCCLUSION_OBJECTS; a sphere's object is
  // albedo[i].w, -1 none of these): object k's oriented patches at k * MRGI_OBJECT_PATCHES + j,
  // xyz the world unit normal, w the facing area (m^2; 0: no patch); where near_field.y is 1,
  // each patch's radiance lit by the shadowed lights (rgb albedo x E / pi). object_centre[k]
  // xyz the object's centre (world, metres), w the radius (metres) within which a virtual
  // point is taken to be on its surface and gets none of its light. object_far[k] x the sum of
  // pi r^2 over its spheres here (m^2), y its bounding radius (m) (far_field_scale).
  // object_loss[k] rgb the flux its surroundings reflect less (W, real_bounce_loss), w the
  // spread (m); object_base[k] xyz where that loss is emitted from (world, metres).
  vec4 object_patch[MRGI_MAX_OCCLUSION_OBJECTS * MRGI_OBJECT_PATCHES];
  vec4 patch_radiance[MRGI_MAX_OCCLUSION_OBJECTS * MRGI_OBJECT_PATCHES];
  vec4 object_centre[MRGI_MAX_OCCLUSION_OBJECTS];
  vec4 object_far[MRGI_MAX_OCCLUSION_OBJECTS];
  vec4 object_loss[MRGI_MAX_OCCLUSION_OBJECTS];
  vec4 object_base[MRGI_MAX_OCCLUSION_OBJECTS];
};

#ifdef __cplusplus
static_assert(sizeof(EnvOcclusionSet) == 16 * (2 + 12 + 2 * MRGI_MAX_OCCLUDER_SPHERES + 2 * MRGI_MAX_OCCLUSION_REGIONS +
                                              (2 * MRGI_OBJECT_PATCHES + 4) * MRGI_MAX_OCCLUSION_OBJECTS),
              "std140 mirror");
#undef MRGI_FN
}  // namespace mrgi::shader
#else
#undef MRGI_FN
#endif
#endif  // MRGI_OCCLUSION_MATH_H
