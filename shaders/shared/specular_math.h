// Math of reflective and refractive virtual objects in DIR (Knecht et al. 2013, "Reflective and
// refractive objects for mixed reality", ../shared/papers/reflective-refractive-caustics-dir.md),
// shared by the specular stage's shaders (shaders/specular/) and the C++ tests under the rules of
// mrgi_shared.h.
//
//   - Which materials are specular (specular_kind): smooth metal reflects the scene as an image
//     (a mirror); a transmissive material refracts it (glass). Everything else is left to the
//     technique's diffuse and glossy shading.
//   - The Fresnel factors eta_1 (reflected) and eta_2 (refracted) of eq. 9: the exact unpolarised
//     dielectric reflectance at both interfaces of the two-sided refraction (Wyman 2005), Schlick
//     with F0 = base colour for metal; the transmittance colour T_c: the base colour at each of the
//     two interfaces (glTF KHR_materials_transmission tints what passes the surface) times Beer's
//     attenuation over the distance travelled inside (KHR_materials_volume), as Akenine-Moller et
//     al. describe it (the paper's [1]).
//   - The composite of eq. 6-11 (specular_compose).
//   - The impostors' cube (specular_cube_face): six 90 degree faces around a set's centre.
//   - The caustic receiver maps of the fast level (specular/caustics.h): the octahedral map of
//     directions around a lamp (mrgi_shared.h oct_encode) and the squares photons cover in it.
#ifndef MRGI_SPECULAR_MATH_H
#define MRGI_SPECULAR_MATH_H

#include "shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

const int SPECULAR_NONE = 0;
const int SPECULAR_REFLECTIVE = 1;  // a mirror: metallic, smooth
const int SPECULAR_REFRACTIVE = 2;  // glass: transmissive (reflects too, by Fresnel)

// A metal at most this rough shows a reflected image rather than a blur a diffuse technique's
// glossy lobe approximates (GGX alpha = 0.01: a lobe under a degree wide).
const float SPECULAR_MAX_MIRROR_ROUGHNESS = 0.1f;
const float SPECULAR_MIN_MIRROR_METALLIC = 0.5f;

MRGI_FN int specular_kind(float metallic, float roughness, float transmission) {
  if (transmission > 0.0f) return SPECULAR_REFRACTIVE;
  if (metallic >= SPECULAR_MIN_MIRROR_METALLIC && roughness <= SPECULAR_MAX_MIRROR_ROUGHNESS) return SPECULAR_REFLECTIVE;
  return SPECULAR_NONE;
}

// Unpolarised Fresnel reflectance of a smooth dielectric for light arriving at cos_i (> 0) on
// the side of index n_i, eta = n_i / n_t; 1 under total internal reflection.
MRGI_FN float fresnel_dielectric(float cos_i, float eta) {
  float c = clamp(cos_i, 0.0f, 1.0f);
  float sin2_t = eta * eta * max(0.0f, 1.0f - c * c);
  if (sin2_t >= 1.0f) return 1.0f;
  float cos_t = sqrt(1.0f - sin2_t);
  float rs = (eta * c - cos_t) / (eta * c + cos_t);
  float rp = (c - eta * cos_t) / (c + eta * cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

// Snell's law: the direction of `d` (unit, towards the surface) after crossing a surface of unit
// normal n (facing against d), eta = n_i / n_t; w = 0 under total internal reflection (xyz then
// the mirror direction, which is where the light goes).
MRGI_FN vec4 refract_or_reflect(vec3 d, vec3 n, float eta) {
  float cos_i = -dot(d, n);
  float sin2_t = eta * eta * max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return vec4(d + 2.0f * cos_i * n, 0.0f);
  vec3 t = eta * d + (eta * cos_i - sqrt(1.0f - sin2_t)) * n;
  return vec4(normalize(t), 1.0f);
}

MRGI_FN vec3 mirror_direction(vec3 d, vec3 n) { return d - 2.0f * dot(d, n) * n; }

// Schlick's reflectance of a metal (F0 = its base colour) at cos_i.
MRGI_FN vec3 fresnel_metal(vec3 f0, float cos_i) {
  return f0 + (vec3(1.0f) - f0) * schlick_weight(clamp(cos_i, 0.0f, 1.0f));
}

// The colour light keeps through a refractive object: the base colour at the two interfaces
// times Beer's law over `distance_m` inside (attenuation colour reached after
// attenuation_distance_m; <= 0: no absorption, KHR_materials_volume's infinite default).
MRGI_FN vec3 transmittance_colour(vec3 base, vec3 attenuation, float attenuation_distance_m, float distance_m) {
  vec3 tint = base * base;
  if (attenuation_distance_m <= 0.0f) return tint;
  float k = max(distance_m, 0.0f) / attenuation_distance_m;
  vec3 a = clamp(attenuation, vec3(1e-4f), vec3(1.0f));
  return tint * vec3(pow(a.x, k), pow(a.y, k), pow(a.z, k));
}

// Eq. 6-11 for one pixel of a virtual reflective or refractive object, in the compose's linear
// camera units (radiance x exposure; mrgi_shared.h compose_encoded). Per path i (the reflected
// and the refracted ray) with weight w_i (eta_1, or eta_2 T_c):
//   l_rv, l_r    sum_i w_i L_rv,i and sum_i w_i L_r,i (eq. 3-4: L_r,i only for a real lamp's
//                light on a real hit point, eq. 5), tone-mapped like compose's;
//   camera       CI_bp of eq. 9 with eq. 10: sum_i w_i x (the camera's colour at the back-
//                projected real hit where the depth validity test passes; 0 at a virtual hit;
//                the path's own L_r,i where the test fails or the hit is outside the view, which
//                is eq. 9's "L'_r otherwise" path by path: that path then shows its rendered
//                L_rv,i, the others keep the camera's colour);
//   env          L_env (Sec. 4.1.3): sum_i w_i x the environment seen along a ray that leaves
//                the modelled scene.
// Returns L'_final = L_env + CI_bp + alpha' (L'_rv - L'_r), alpha' = CI_bp / L'_r (eq. 7, 11),
// under compose's guards (eps, alpha_max: differential_compose). The paper evaluates v() once
// for the pixel and returns the whole L'_r where it fails; per path, a reflected ray that meets
// nothing modelled no longer throws away the refracted camera image (the exception of Sec. 4.1.3
// for refractive objects is the special case of this).
MRGI_FN vec3 specular_compose(vec3 l_rv, vec3 l_r, vec3 camera, vec3 env, float eps, float alpha_max) {
  return max(env, vec3(0.0f)) + differential_compose(camera, l_r, l_rv, 0.0f, eps, alpha_max);
}

// The impostor cube around a set's centre: face of direction d (+X, -X, +Y, -Y, +Z, -Z) in w,
// its coordinates in [0, 1]^2 in xy, as the face's view matrix (specular_face_axes) projects it.
MRGI_FN vec3 specular_face_forward(int face) {
  if (face == 0) return vec3(1.0f, 0.0f, 0.0f);
  if (face == 1) return vec3(-1.0f, 0.0f, 0.0f);
  if (face == 2) return vec3(0.0f, 1.0f, 0.0f);
  if (face == 3) return vec3(0.0f, -1.0f, 0.0f);
  if (face == 4) return vec3(0.0f, 0.0f, 1.0f);
  return vec3(0.0f, 0.0f, -1.0f);
}
// The face's right and down axes (image x grows along right, y along down), right-handed with
// forward: right x down = forward.
MRGI_FN vec3 specular_face_right(int face) {
  if (face == 0) return vec3(0.0f, 0.0f, 1.0f);
  if (face == 1) return vec3(0.0f, 0.0f, -1.0f);
  if (face == 5) return vec3(1.0f, 0.0f, 0.0f);
  return vec3(-1.0f, 0.0f, 0.0f);
}
MRGI_FN vec3 specular_face_down(int face) {
  if (face == 2) return vec3(0.0f, 0.0f, 1.0f);
  if (face == 3) return vec3(0.0f, 0.0f, -1.0f);
  return vec3(0.0f, -1.0f, 0.0f);
}
// The face's axes above written out per major axis (selects, no per-face lookups: the impostor
// search runs this at every step of every ray, and lavapipe evaluates every branch of a lookup
// chain); SpecularMath.CubeFaceClosedFormMatchesTheFaceAxes holds it to them.
MRGI_FN vec3 specular_cube_face(vec3 d) {
  vec3 a = abs(d);
  bool x_major = a.x >= a.y && a.x >= a.z;
  bool y_major = !x_major && a.y >= a.z;
  float sx = d.x >= 0.0f ? 1.0f : -1.0f, sy = d.y >= 0.0f ? 1.0f : -1.0f, sz = d.z >= 0.0f ? 1.0f : -1.0f;
  float z = x_major ? a.x : (y_major ? a.y : a.z);
  float u = x_major ? sx * d.z : (y_major ? -d.x : -sz * d.x);
  float v = y_major ? sy * d.z : -d.y;
  float face = x_major ? (sx > 0.0f ? 0.0f : 1.0f) : (y_major ? (sy > 0.0f ? 2.0f : 3.0f) : (sz > 0.0f ? 4.0f : 5.0f));
  vec2 uv = vec2(u, v) / max(z, 1e-20f);
  return vec3(clamp(uv * 0.5f + vec2(0.5f), vec2(0.0f), vec2(1.0f)), face);
}

// ---- caustic receiver maps ----------------------------------------------------------------------

// Whether a caustic photon that landed at distance `photon` (m, from the camera in the camera's
// splat, from the lamp in a receiver map) lit the surface point at distance `surface` along the
// same ray: within 3 % + 1 cm (the depth sensor's noise and a splat's extent on a tilted surface).
MRGI_FN bool caustic_same_surface(float surface, float photon) {
  return abs(surface - photon) <= 0.03f * surface + 0.01f;
}

// Solid angle (sr) of one texel of a size x size octahedral map at unit direction d. The map
// takes the octahedron |x| + |y| + |z| = 1 to [-1, 1]^2 with area kept (the lower half's folding
// only moves triangles), and an area element dA at the octahedron's point P = d / l1(d) subtends
// dA cos / |P|^2 with cos = 1 / (sqrt(3) |P|) and dA = sqrt(3) du dv: du dv / |P|^3, so
// (2 / size)^2 l1(d)^3 (1 at the poles, 3 sqrt(3) at the faces' centres; 4 pi over the map).
MRGI_FN float oct_texel_solid_angle(vec3 d, float size) {
  float l1 = abs(d.x) + abs(d.y) + abs(d.z);
  float texel = 2.0f / size;
  return texel * texel * l1 * l1 * l1;
}

// The square a photon covers in a receiver map: side in texels (x) and the area (m^2) those
// texels cover on the surface it landed on (y), so each texel's irradiance is flux / y and the
// square holds the photon's flux whatever its side. spacing: the photon's footprint (m, the
// distance to where its neighbours landed); r: its distance from the lamp (m); cos_l: the cosine
// between the surface's normal and the lamp's ray there; texel_sr: oct_texel_solid_angle there.
// The side is a whole number of texels: a point of side n covers exactly n x n texel centres,
// while what a fractional side covers depends on how the rasteriser rounds it. Within that
// rounding the square covers the photon's footprint on the surface (spacing^2) at any distance
// and tilt.
MRGI_FN vec2 caustic_receiver_square(float spacing, float r, float cos_l, float texel_sr, float min_side,
                                     float max_side) {
  float c = max(cos_l, 0.1f);  // grazing: the square's area stays finite
  float side = spacing * sqrt(c) / (max(r, 1e-4f) * sqrt(max(texel_sr, 1e-20f)));
  side = clamp(floor(side + 0.5f), max(floor(min_side), 1.0f), max(floor(max_side), 1.0f));
  return vec2(side, side * side * texel_sr * r * r / c);
}

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef MRGI_FN
#endif

#endif  // MRGI_SPECULAR_MATH_H
