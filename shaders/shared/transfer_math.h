// Per-sample math of the image-space radiance transfer technique (`ssrt`, paper
// "Image-Space Illumination for Augmented Reality in Dynamic Environments", Sec. 5), written once
// in the GLSL subset that also compiles as C++ with GLM (same rules as shared/mrgi_shared.h), so
// the CPU tests check exactly what the shaders run.
//
// GLSL:  #include "shared/mrgi_shared.h"  then  #include "shared/transfer_math.h"
// C++:   #include "shared/transfer_math.h"       (everything in namespace mrgi::shader)
#ifndef MRGI_SSRT_MATH_H
#define MRGI_SSRT_MATH_H

#include "../shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
using glm::cos;
using glm::sqrt;
#define SSRT_FN inline
#else
#define SSRT_FN
#endif

// ---- continuous visibility, eq. 7-9 --------------------------------------------------------

// Eq. 9 names chi = cos(median(alpha)/2) with alpha the angles between neighbouring sample
// directions (spherical Delaunay edges). Read literally, chi is ~1 for any useful N, and eq. 8
// then makes K = 1 - t.w, a cosine ramp over the whole hemisphere that ignores the sampling
// density, contradicting the text ("chi is related to the angle between adjacent sampling
// directions", "the angular distance ... has to lie inside the threshold chi"). Eq. 8 compares
// chi with 1 - t.w, a one-minus-cosine, so the threshold that matches the text is the
// one-minus-cosine of half the median angle (the Nyquist half-spacing): K reaches 1 exactly when
// the occluder lies half a sample spacing or more away from w_j, i.e. in another sample's cell.
SSRT_FN float ssrt_chi_from_median_angle(float median_angle_rad) {
  return max(1.0f - cos(0.5f * median_angle_rad), 1e-6f);
}

// A sender (occluder) point s seen from the receiver x: the unit direction t = (s - x)/|s - x|
// and the squared distance, which eq. 7-8 and eq. 10-12 all start from. A pass evaluating both
// for one point computes them once (ssrt_sender, then the *_from functions): each is a square
// root and three divisions per lane, paid by every lane on a CPU device. len2 <= 1e-12
// (s == x): degenerate, t is 0.
struct SsrtSender {
  vec3 t;
  float len2;
};
SSRT_FN SsrtSender ssrt_sender(vec3 x, vec3 s) {
  vec3 d = s - x;
  SsrtSender r;
  r.len2 = dot(d, d);
  r.t = r.len2 > 1e-12f ? d / sqrt(r.len2) : vec3(0.0f);
  return r;
}

// Eq. 7-8: visibility of direction w (unit) at x when the depth test found the surface point s
// in front of the sample: t = (s - x)/|s - x|, K = min(chi, 1 - t.w)/chi. 0 = blocked (the
// occluder lies along w), rising to 1 as the occluder's direction leaves w's cell. A degenerate
// s == x cannot block anything and counts as visible.
SSRT_FN float ssrt_visibility_k_from(SsrtSender s, vec3 w, float chi) {
  if (!(s.len2 > 1e-12f)) return 1.0f;
  return clamp(min(chi, 1.0f - dot(s.t, w)) / chi, 0.0f, 1.0f);
}
SSRT_FN float ssrt_visibility_k(vec3 x, vec3 s, vec3 w, float chi) {
  return ssrt_visibility_k_from(ssrt_sender(x, s), w, chi);
}

// ---- one-bounce indirect, eq. 10-12 ---------------------------------------------------------

// Eq. 12 as printed, max(0, sgn(n(x).(-t))), would cut exactly the transfers eq. 11 keeps (it is
// positive only when the sender lies behind the receiver's tangent plane); the text says G
// "suppresses light transfer from points facing away from x", which is the sender's normal:
// G = max(0, sgn(n(s).(-t))). That is what is implemented.
SSRT_FN float ssrt_facing_gate(vec3 n_s, vec3 t) { return dot(n_s, -t) > 0.0f ? 1.0f : 0.0f; }

// Eq. 11: F = (n(x).t)(n(s).(-t)) / (pi |x - s|^2), times the area a sample stands for. The paper
// leaves out the sender's area, which makes F's unit 1/m^2 and its scale depend on metres; like
// SSDO (Ritschel et al. 2009, eq. 2) each sample stands for a patch of area
// `sample_area` = pi r_max^2 / N. The distance is clamped below at `min_dist` (metres) so a
// sender next to the receiver cannot blow up (the 1/d^2 singularity of point-to-point transfer),
// and F is limited to 1 (a patch cannot send more than it receives). Cosines are clamped at 0.
SSRT_FN float ssrt_form_factor_from(SsrtSender s, vec3 n_x, vec3 n_s, float sample_area,
                                    float min_dist) {
  if (!(s.len2 > 1e-12f)) return 0.0f;
  float cos_r = max(dot(n_x, s.t), 0.0f);
  float cos_s = max(dot(n_s, -s.t), 0.0f);
  float d2 = max(s.len2, min_dist * min_dist);
  return min(cos_r * cos_s * sample_area / (MRGI_PI * d2), 1.0f);
}
SSRT_FN float ssrt_form_factor(vec3 x, vec3 n_x, vec3 s, vec3 n_s, float sample_area,
                               float min_dist) {
  return ssrt_form_factor_from(ssrt_sender(x, s), n_x, n_s, sample_area, min_dist);
}

// One term of eq. 10: the sender s, lit by the dominant directional light (unit direction to
// the light `l_dir`, irradiance `e_light`), reflects albedo_s * E / pi towards x, weighted by
// occlusion (1 - K), the form factor and the facing gate. Returns the irradiance it adds at x
// (linear RGB); the receiver's albedo is applied by the composite.
SSRT_FN vec3 ssrt_indirect_term_from(SsrtSender s, vec3 n_x, vec3 n_s, vec3 albedo_s, float k,
                                     vec3 l_dir, vec3 e_light, float sample_area,
                                     float min_dist) {
  if (!(s.len2 > 1e-12f)) return vec3(0.0f);
  float f = ssrt_form_factor_from(s, n_x, n_s, sample_area, min_dist);
  float g = ssrt_facing_gate(n_s, s.t);
  vec3 sender_radiance = albedo_s * e_light * (max(dot(n_s, l_dir), 0.0f) / MRGI_PI);
  // F already holds 1/pi of the Lambertian kernel; radiance * pi * F is the irradiance received.
  return (1.0f - clamp(k, 0.0f, 1.0f)) * g * MRGI_PI * f * sender_radiance;
}
SSRT_FN vec3 ssrt_indirect_term(vec3 x, vec3 n_x, vec3 s, vec3 n_s, vec3 albedo_s, float k,
                                vec3 l_dir, vec3 e_light, float sample_area, float min_dist) {
  return ssrt_indirect_term_from(ssrt_sender(x, s), n_x, n_s, albedo_s, k, l_dir, e_light,
                                 sample_area, min_dist);
}

// ---- transfer and shading -------------------------------------------------------------------

// Diffuse radiance transfer of one sample direction w at normal n (eq. 6 without the albedo):
// K (w.n) dw / pi, so that dot(transfer, L_sh) is the outgoing radiance of a white Lambertian
// surface under SH radiance L. (The paper leaves the 1/pi in the albedo; keeping it here makes
// the estimated l a radiance.) Back-facing directions transfer nothing.
SSRT_FN float ssrt_transfer_weight(vec3 n, vec3 w, float k, float solid_angle) {
  return k * max(dot(n, w), 0.0f) * solid_angle / MRGI_PI;
}

// ---- differential composite, eq. 13-15 ------------------------------------------------------

// Reinhard et al. 2002 global operator (the paper's [23]): scaled luminance Ls = key / avg * L,
// Ld = Ls (1 + Ls / white^2) / (1 + Ls). `avg` is the buffer's (log-)average; <= 0 gives 0.
// `white` is Reinhard's L_white, the smallest scaled luminance mapped to pure white: the curve
// reaches 1 there and is held at 1 beyond (which also keeps HDR input finite).
SSRT_FN float ssrt_reinhard(float l, float key, float avg, float white) {
  if (!(avg > 0.0f) || !(l > 0.0f)) return 0.0f;
  float w = max(white, 1e-6f);
  float ls = min(key * (l / avg), w);
  return min(ls / (1.0f + ls) * (1.0f + ls / (w * w)), 1.0f);
}

// Eq. 13: I_d = I_c (1 + T(R'_d) - T(R_d)). The paper tone-maps each buffer with its own
// average; two different scales would change every pixel even where the virtual object has no
// effect (R'_d = R_d), so both use the real buffer's average `avg_real`: pixels without a delta
// keep I_c exactly. The factor is clamped at 0 (light cannot be negative).
SSRT_FN vec3 ssrt_direct_differential(vec3 camera, float r_d, float r_d_virtual, float key,
                                      float avg_real, float white) {
  float delta = ssrt_reinhard(r_d_virtual, key, avg_real, white) -
                ssrt_reinhard(r_d, key, avg_real, white);
  return camera * max(1.0f + delta, 0.0f);
}

// Eq. 14: I_i = R'_i where it differs from R_i, else 0. "Differs" is relative, with tolerance
// `rel_tol` on the luminance, so float noise between two evaluations of the same transfer does
// not leak real-only bounce light into the frame.
SSRT_FN vec3 ssrt_indirect_select(vec3 r_i, vec3 r_i_virtual, float rel_tol) {
  float a = luminance(r_i);
  float b = luminance(r_i_virtual);
  float scale = max(max(abs(a), abs(b)), 1e-12f);
  return abs(b - a) > rel_tol * scale ? r_i_virtual : vec3(0.0f);
}

// Eq. 15 for a real pixel: I_final = I_d + I_i, with the bounce light reflected by the pixel's
// albedo (Lambertian: albedo / pi of the irradiance).
SSRT_FN vec3 ssrt_compose_real(vec3 camera, float r_d, float r_d_virtual, vec3 r_i,
                               vec3 r_i_virtual, vec3 albedo, float key, float avg_real,
                               float white, float rel_tol) {
  vec3 direct = ssrt_direct_differential(camera, r_d, r_d_virtual, key, avg_real, white);
  vec3 bounce = ssrt_indirect_select(r_i, r_i_virtual, rel_tol) * albedo / MRGI_PI;
  return max(direct + bounce, vec3(0.0f));
}

// ---- up-sampling (fast levels) ---------------------------------------------------------------

// Catmull-Rom weights of the 4 taps around fraction t (shade.comp's bicubic, paper OursFast).
SSRT_FN vec4 ssrt_catmull_rom(float t) {
  float t2 = t * t, t3 = t2 * t;
  return vec4(-0.5f * t3 + t2 - 0.5f * t, 1.5f * t3 - 2.5f * t2 + 1.0f,
              -1.5f * t3 + 2.0f * t2 + 0.5f * t, 0.5f * t3 - 0.5f * t2);
}

// Whether shading a tile can move none of its pixels by a visible amount, so the camera frame
// may stand (shade_tiles.comp), from its bicubic footprint's cells, all present and real (the
// weights then sum to 1): d_max = max |R'_d - R_d|, i_max = max component of R'_i over the
// cells where R'_i != R_i (0 where equal: eq. 14's select is 0 there), R_d in [lo, hi].
// A real pixel's composite is camera + alpha (L_rv - L_r) with alpha <= camera / L_r
// (mrgi_shared.h differential_compose; the exposure and the clip at 1 only shrink the
// difference), L_r = A R_d and L_rv = A (R'_d + select(R_i, R'_i) / pi): shading moves the
// linear camera value c by at most c r, r = |R'_d - R_d + select / pi| / R_d, and the 8-bit
// sRGB value by at most 255 max(x srgb'(x)) r = 112.1 r (at x = 1: 1.055 / 2.4 x^(1 / 2.4)).
// Catmull-Rom's two negative weights per axis sum to -t (1 - t) / 2 >= -1/8, so sum |w| <=
// 1.25^2 = 1.5625 in 2D and the negative weights sum to at most 0.28125: a pixel's R_d is at
// least lo - 0.28125 (hi - lo), its numerator at most 1.5625 (d_max + i_max / pi). With
// tolerance 2^-7 no pixel moves by more than 0.88 of a level.
SSRT_FN bool ssrt_tile_invisible(float d_max, float i_max, float lo, float hi, float tolerance) {
  float r_d_lower = lo - 0.28125f * (hi - lo);
  return r_d_lower > 0.0f && 1.5625f * (d_max + i_max / MRGI_PI) <= tolerance * r_d_lower;
}

// ---- GPU-side data -------------------------------------------------------------------------

// The estimated light as the passes read it (std140 uniform; vec4 members only so GLM's layout
// is the same). sh[i].xyz: RGB radiance SH coefficient i, sh[i].w: its luminance, the white
// light the paper's transfer uses (Sec. 5). dominant: xyz unit direction towards the dominant
// light, w 1 when it exists; dominant_irradiance.rgb: its irradiance at normal incidence.
struct SsrtLight {
  vec4 sh[16];
  vec4 dominant;
  vec4 dominant_irradiance;
};

// Sample directions the transfer's uniform buffer holds, all levels together (16 KiB, the
// smallest maxUniformBufferRange Vulkan allows).
#define SSRT_MAX_SAMPLE_DIRECTIONS 1024

// One visibility sample (std430; see runtime/src/technique/ssrt/sample_directions.h).
struct SsrtSample {
  vec4 direction_and_radius;  // xyz unit direction (world), w displacement / radius in (0, 1]
  vec4 sh_weights[4];         // Y_0..15(w) * solid angle
};

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef SSRT_FN
#endif

#endif  // MRGI_SSRT_MATH_H
