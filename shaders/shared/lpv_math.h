// Light propagation volume math (Kaplanyan & Dachsbacher 2010, "Cascaded light propagation
// volumes"; used by the DLPV paper, delta-light-propagation-volumes.md Sec. 4), shared by the
// shaders (shaders/gi/lpv_*.comp) and the C++ tests, under the rules of mrgi_shared.h.
//
// A cell holds, per colour channel, the 2-band SH (4 coefficients, Sloan order as sh_basis16's
// first vec4) of the radiant INTENSITY I(w) [W/sr] leaving the cell towards w.
//   - A virtual point light (VPL) of reflected flux P on a surface of normal n has the intensity
//     of a diffuse emitter, I(w) = P / pi * max(0, n . w) (paper eq. 12): lpv_vpl_intensity.
//   - Propagation gathers, for each of the 6 neighbours, the flux through the 5 faces of this
//     cell that the neighbour's centre sees: P_f = solid_angle_f * I_neighbour(w_f), w_f towards
//     the face's centre, and re-emits it from this cell's centre as a diffuse emitter facing the
//     face (P_f / pi * max(0, n_f . w)). The face solid angles are exact (a unit square at 1.5
//     cells: 4 asin(1/10); the 4 side faces share the rest of the near face's 2 pi / 3), so the
//     6 neighbours' faces tile the sphere and an isotropic cell loses no flux in one step.
//   - Irradiance at a surface of normal n inside a cell of size s [m], from the accumulated
//     intensity (lpv_irradiance): the light passing through the cell's cross-section s^2,
//     E(n) = 1/s^2 * integral I(-w) max(0, n . w) dw = 1/s^2 sum_lm c_lm A_l Y_lm(-n).
#ifndef MRGI_LPV_MATH_H
#define MRGI_LPV_MATH_H

#include "shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

const float LPV_SOLID_ANGLE_FRONT = 0.40066968f;  // 4 asin(0.1): the far face, 1.5 cells away
const float LPV_SOLID_ANGLE_SIDE = 0.42343134f;   // (2 pi / 3 - front) / 4: each side face

// Y00, Y1-1, Y10, Y11 of unit direction d (= sh_basis16(d).c0).
MRGI_FN vec4 sh_basis4(vec3 d) {
  return vec4(0.282094791773878f, -0.488602511902920f * d.y, 0.488602511902920f * d.z,
              -0.488602511902920f * d.x);
}
MRGI_FN float sh4_eval(vec4 c, vec3 d) { return dot(c, sh_basis4(d)); }

// Bands 0-1 rotated by `r` (a rotation of directions): band 1 is k v . w with v = (-c.w, -c.y,
// c.z), a vector, so it turns with r; band 0 does not turn. sh4_eval(result, d) =
// sh4_eval(c, transpose(r) d). (sh_rotate16 in mrgi_shared.h for bands 0-3.)
MRGI_FN vec4 sh4_rotate(vec4 c, mat3 r) {
  vec3 v = r * vec3(-c.w, -c.y, c.z);
  return vec4(c.x, -v.y, v.z, -v.x);
}

// SH2 of the clamped cosine max(0, n . w): A_l Y_lm(n) with A_0 = pi, A_1 = 2 pi / 3.
MRGI_FN vec4 sh4_cosine_lobe(vec3 n) {
  vec4 y = sh_basis4(n);
  return vec4(MRGI_PI * y.x, 2.0f * MRGI_PI / 3.0f * y.y, 2.0f * MRGI_PI / 3.0f * y.z,
              2.0f * MRGI_PI / 3.0f * y.w);
}

// The intensity SH of a diffuse emitter of total flux `flux` facing `n` (paper eq. 12).
MRGI_FN vec4 lpv_vpl_intensity(vec3 n, float flux) { return sh4_cosine_lobe(n) * (flux / MRGI_PI); }

// Total flux [W] an intensity SH emits over the sphere: c00 * sqrt(4 pi).
MRGI_FN float sh4_total_flux(vec4 c) { return c.x * 3.544907701811032f; }

// Axis i of the 6 neighbours: +x, -x, +y, -y, +z, -z.
MRGI_FN vec3 lpv_axis(int i) {
  float s = (i & 1) == 0 ? 1.0f : -1.0f;
  int a = i >> 1;
  return vec3(a == 0 ? s : 0.0f, a == 1 ? s : 0.0f, a == 2 ? s : 0.0f);
}

// Damping of negative flux (antiradiance) by the directional derivative of the intensity along
// the propagation (paper Sec. 4.4): g = |I_src(w) - I_dst(w)| / (|I_src(w)| + |I_dst(w)|) is 0
// where the field is smooth along w and 1 where the value is a step (a shadow injected into
// one cell, next to light); negative flux is scaled by 1 / (1 + strength g). Positive flux is
// never damped. strength 0: none. (The paper names the cue, not the formula; this is ours.)
MRGI_FN float lpv_negative_damping(float i_src, float i_dst, float strength) {
  float g = abs(i_src - i_dst) / (abs(i_src) + abs(i_dst) + 1e-30f);
  return 1.0f / (1.0f + strength * g);
}

// What one channel of a cell gathers through its face of normal n_f from the neighbour at
// offset a (a unit axis; n_f != a): `src` is the neighbour's intensity SH, `dst` the cell's own
// (previous step, for the damping). With a and n_f constants (the shader spells out all 30
// pairs, LPV_GATHER_ALL) every direction, basis and lobe folds to a constant.
MRGI_FN vec4 lpv_gather_face(vec4 src, vec4 dst, vec3 a, vec3 n_f, float negative_damping) {
  vec3 w = normalize(n_f * 0.5f - a);
  float solid = dot(n_f, a) < -0.5f ? LPV_SOLID_ANGLE_FRONT : LPV_SOLID_ANGLE_SIDE;
  float i_src = sh4_eval(src, w);
  float flux = solid * i_src;
  if (flux < 0.0f) flux *= lpv_negative_damping(i_src, sh4_eval(dst, w), negative_damping);
  return sh4_cosine_lobe(n_f) * (flux / MRGI_PI);
}

// What one channel of a cell gathers in one propagation step from its neighbour at
// lpv_axis(k): the 5 faces that neighbour sees (not the one between them, seen edge-on).
MRGI_FN vec4 lpv_gather_from(vec4 src, vec4 dst, int k, float negative_damping) {
  vec3 a = lpv_axis(k);
  vec4 sum = vec4(0.0f);
  for (int f = 0; f < 6; ++f) {
    if (f == k) continue;
    sum += lpv_gather_face(src, dst, a, lpv_axis(f), negative_damping);
  }
  return sum;
}

// Irradiance [W/m^2] at a surface of normal n from a cell's accumulated intensity SH, cell
// size s [m]; may be negative in a delta volume (light taken away).
MRGI_FN float lpv_irradiance(vec4 intensity, vec3 n, float cell_size) {
  return dot(intensity, sh4_cosine_lobe(n * -1.0f)) / (cell_size * cell_size);
}

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef MRGI_FN
#endif

#endif  // MRGI_LPV_MATH_H
