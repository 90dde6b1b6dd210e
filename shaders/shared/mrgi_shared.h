// Math shared by the shaders and the C++ side (reference renderer, tests), written once in the
// subset of GLSL that also compiles as C++ with GLM, so CPU unit tests check what shaders run.
//
// GLSL:  #extension GL_GOOGLE_include_directive : require
//        #include "shared/mrgi_shared.h"
// C++:   #include "shared/mrgi_shared.h"   (everything is in namespace mrgi::shader)
//
// Rules for this file: float literals carry an `f` suffix (GLM does not mix float and double),
// no swizzles (GLM needs GLM_FORCE_SWIZZLE for them), no out-parameters or arrays (structs
// instead), every function MRGI_FN.
#ifndef MRGI_SHARED_H
#define MRGI_SHARED_H

#ifdef __cplusplus
#include <cstdint>

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
namespace mrgi::shader {
using glm::abs;
using glm::acos;
using glm::asin;
using glm::atan;
using glm::clamp;
using glm::cos;
using glm::dot;
using glm::exp2;
using glm::floor;
using glm::isinf;
using glm::isnan;
using glm::length;
using glm::log2;
using glm::mat3;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::packSnorm2x16;
using glm::pow;
using glm::sin;
using glm::smoothstep;
using glm::sqrt;
using glm::tan;
using glm::transpose;
using glm::unpackSnorm2x16;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using glm::ivec2;
using uint = uint32_t;
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

const float MRGI_PI = 3.14159265358979f;

// ---- integer arithmetic ---------------------------------------------------------------------

// a / b for 0 <= a < 2^20 and 1 <= b < 2^20 (per component), exactly the integer quotient,
// through one float division: a CPU Vulkan device runs an integer division by a value it cannot
// see at compile time as one scalar divide per SIMD lane (x86 has no vector integer divide;
// ssrt's transfer made four per sample), a float division as one vector instruction. Exact
// where the division is IEEE (lavapipe's is: tests/vulkan/test_shader_math.cpp checks it on
// the device): a = k b + r gives a / b = k + r / b, at least 1 / b below k + 1, which is more
// than the float's rounding step there (1 / b > (k + 1) 2^-24 while b (k + 1) <= a + b < 2^24);
// for r = 0 the quotient is representable.
MRGI_FN ivec2 div_nonneg(ivec2 a, int b) { return ivec2(vec2(a) / float(b)); }
MRGI_FN int div_nonneg1(int a, int b) { return int(float(a) / float(b)); }

// Workgroup order for CPU Vulkan devices. Lavapipe (Mesa 22.3, lp_cs_tpool.c) splits a
// dispatch's n workgroups statically: with T worker threads, thread i runs the contiguous run
// [i n / T, (i + 1) n / T) of the linear workgroup index (x fastest), so with 2 threads one
// runs the top half of the image and the other the bottom half. Where the cost differs
// between the halves (sky against a floor full of samples, rays that miss against rays that
// march) one thread idles while the other finishes: ssrt's fast level ran with one core idle
// for 11 % of its frame. This maps the index a worker runs, k, to the tile the invocation
// computes: the k of quarter q of the range (q = 0..3) take the tiles congruent to q mod 4,
// so each half and each quarter of the range covers the whole grid in stripes (balanced for
// 2 and 4 threads); the last n mod 4 keep their place. A bijection on [0, n); on a GPU the
// order of workgroups does not matter.
MRGI_FN int spread_workgroup_index(int k, int n) {
  int bulk = n - n % 4;
  if (k >= bulk) return k;
  int quarter = bulk / 4;
  int q = div_nonneg1(k, quarter);
  return 4 * (k - q * quarter) + q;
}

// ---- colour -------------------------------------------------------------------------------

// sRGB transfer function (IEC 61966-2-1), per channel, input clamped to [0, 1].
MRGI_FN float srgb_encode1(float linear) {
  float c = clamp(linear, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
}
MRGI_FN float srgb_decode1(float encoded) {
  float c = clamp(encoded, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}
MRGI_FN vec3 srgb_encode(vec3 linear) {
  return vec3(srgb_encode1(linear.x), srgb_encode1(linear.y), srgb_encode1(linear.z));
}
MRGI_FN vec3 srgb_decode(vec3 encoded) {
  return vec3(srgb_decode1(encoded.x), srgb_decode1(encoded.y), srgb_decode1(encoded.z));
}

// Y'CbCr camera frames (mrgi/frame.h YuvImage), converted by recon/yuv_to_rgb.comp and read
// where the host needs the colour (light/camera_color.h): the layouts and matrices by number.
#define MRGI_YUV_NV12 0
#define MRGI_YUV_YUYV 1
#define MRGI_YUV_BT601 0
#define MRGI_YUV_BT709 1

// One Y'CbCr sample (8-bit codes y, cb, cr) as the R'G'B' the colour frame holds (gamma-encoded,
// taken as sRGB), [0, 1] per channel: ITU-R BT.601 or BT.709 luma coefficients (Kr, Kb), limited
// range (Y' 16-235 and Cb Cr 16-240 span 219 and 224 codes) or full (0-255, JFIF):
//   R' = Y' + 2 (1 - Kr) Pr,  B' = Y' + 2 (1 - Kb) Pb,  G' = Y' - (2 Kb (1 - Kb) Pb + 2 Kr (1 - Kr) Pr) / Kg.
MRGI_FN vec3 yuv_to_encoded_rgb(float y, float cb, float cr, int matrix, bool full_range) {
  float kr = matrix == MRGI_YUV_BT709 ? 0.2126f : 0.299f;
  float kb = matrix == MRGI_YUV_BT709 ? 0.0722f : 0.114f;
  float kg = 1.0f - kr - kb;
  float luma = full_range ? y / 255.0f : (y - 16.0f) / 219.0f;
  float pb = (cb - 128.0f) / (full_range ? 255.0f : 224.0f);
  float pr = (cr - 128.0f) / (full_range ? 255.0f : 224.0f);
  vec3 rgb = vec3(luma + 2.0f * (1.0f - kr) * pr, luma - (2.0f * kb * (1.0f - kb) * pb + 2.0f * kr * (1.0f - kr) * pr) / kg,
                  luma + 2.0f * (1.0f - kb) * pb);
  return clamp(rgb, vec3(0.0f), vec3(1.0f));
}

// The same as 8-bit codes packed r | g << 8 | b << 16 (rounded to nearest).
MRGI_FN uint yuv_to_rgb8_packed(float y, float cb, float cr, int matrix, bool full_range) {
  vec3 c = floor(yuv_to_encoded_rgb(y, cb, cr, matrix, full_range) * 255.0f + vec3(0.5f));
  return uint(c.x) | (uint(c.y) << 8u) | (uint(c.z) << 16u);
}

// ---- microfacet BRDF -----------------------------------------------------------------------

// GGX (Trowbridge-Reitz) distribution times Smith's height-correlated visibility, D(h) V(l, v),
// for unit normal n and unit directions l (towards the light) and v (towards the viewer), both
// away from the surface; alpha = roughness^2 (glTF metallic-roughness). The specular BRDF is this
// times the Fresnel term (shaders/common/surface_shading.glsl brdf; gi VPL lobes,
// shared/vpl_math.h vpl_intensity). Roughness 0 is a mirror: D is a delta the caller must not
// sample (its value here is 0 or NaN).
MRGI_FN float ggx_d_vis(vec3 n, vec3 l, vec3 v, float roughness) {
  vec3 h = normalize(l + v);
  float nl = max(dot(n, l), 0.0f), nv = max(dot(n, v), 1e-4f), nh = max(dot(n, h), 0.0f);
  float a = roughness * roughness, a2 = a * a;
  float denom = nh * nh * (a2 - 1.0f) + 1.0f;
  float d = a2 / (MRGI_PI * denom * denom);
  float vis = 0.5f / max(nl * sqrt(nv * nv * (1.0f - a2) + a2) + nv * sqrt(nl * nl * (1.0f - a2) + a2), 1e-6f);
  return d * vis;
}
// Schlick's Fresnel factor (1 - cos)^5 (the caller mixes F0 towards 1 by it); pow-free.
MRGI_FN float schlick_weight(float cos_theta) {
  float m = 1.0f - clamp(cos_theta, 0.0f, 1.0f), m2 = m * m;
  return m2 * m2 * m;
}

// Rec. 709 / sRGB primaries luminance of linear RGB.
MRGI_FN float luminance(vec3 linear_rgb) {
  return dot(linear_rgb, vec3(0.2126f, 0.7152f, 0.0722f));
}

// The camera model (docs/DESIGN.md, capture.json `exposure`): linear radiance times exposure is the
// linear sensor value, clipped at 1 (sensor saturation), then the sRGB curve. Compose and the
// reference renderer both use it, so both "see" with the same camera. Negative or NaN-free
// input is assumed; values below 0 clip to 0.
MRGI_FN vec3 camera_response(vec3 radiance, float exposure) {
  return srgb_encode(radiance * exposure);
}
// Inverse of camera_response for unsaturated values: sRGB camera value -> linear radiance.
// exposure <= 0 is treated as 1 (never divides by zero).
MRGI_FN vec3 camera_to_radiance(vec3 encoded, float exposure) {
  float e = exposure > 0.0f ? exposure : 1.0f;
  return srgb_decode(encoded) / e;
}

// ---- coarse geometry lookups ----------------------------------------------------------------

// Camera-space depth where the camera ray `ray` (any point on it with z = 1) meets the tangent
// plane of a G-buffer texel (camera-space point `p`, unit normal `n`). A coarse G-buffer (one
// texel per 4x4 pixels at ssrt's fast levels) holds the surface at the texel centre; a sample
// that projects 2 px from it on a sloped floor would read that centre's depth, several per cent
// off, and the 1 % occluder bias would find it blocked by its own surface. The plane keeps the
// lookup exact on planar surfaces. Falls back to p.z where the ray grazes the plane or the plane
// depth leaves p.z by more than `max_relative` of it (a depth edge, not a plane).
MRGI_FN float tangent_plane_depth(vec3 ray, vec3 p, vec3 n, float max_relative) {
  float denom = dot(n, ray);
  float z = abs(denom) > 1e-4f ? dot(n, p) / denom : p.z;
  bool ok = z > 0.0f && abs(z - p.z) <= max_relative * p.z;
  return ok ? z : p.z;
}

// ---- normals --------------------------------------------------------------------------------

// Octahedral mapping of a unit vector to [-1, 1]^2 (Cigolle et al. 2014, "A Survey of Efficient
// Representations for Independent Unit Vectors").
MRGI_FN vec2 sign_not_zero(vec2 v) {
  return vec2(v.x >= 0.0f ? 1.0f : -1.0f, v.y >= 0.0f ? 1.0f : -1.0f);
}
MRGI_FN vec2 oct_encode(vec3 n) {
  vec3 a = vec3(abs(n.x), abs(n.y), abs(n.z));
  float l1 = a.x + a.y + a.z;
  vec2 p = vec2(n.x, n.y) * (1.0f / max(l1, 1e-20f));
  if (n.z < 0.0f) {
    p = (vec2(1.0f) - vec2(abs(p.y), abs(p.x))) * sign_not_zero(p);
  }
  return p;
}
MRGI_FN vec3 oct_decode(vec2 e) {
  vec3 v = vec3(e.x, e.y, 1.0f - abs(e.x) - abs(e.y));
  if (v.z < 0.0f) {
    vec2 xy = (vec2(1.0f) - vec2(abs(v.y), abs(v.x))) * sign_not_zero(vec2(v.x, v.y));
    v.x = xy.x;
    v.y = xy.y;
  }
  return normalize(v);
}
// Two snorm16 in one uint (for R32_UINT normal buffers).
MRGI_FN uint oct_pack(vec3 n) { return packSnorm2x16(oct_encode(n)); }
MRGI_FN vec3 oct_unpack(uint p) { return oct_decode(unpackSnorm2x16(p)); }

// ---- spherical harmonics --------------------------------------------------------------------

// Real SH basis, bands 0..3 (16 coefficients), orthonormal over the sphere, with the sign
// convention and index order of Sloan, "Stupid Spherical Harmonics (SH) Tricks" (2008),
// appendix: index l*(l+1)+m, m = -l..l. `d` must be unit length.
struct SH16 {
  vec4 c0;  // Y00, Y1-1, Y10, Y11
  vec4 c1;  // Y2-2, Y2-1, Y20, Y21
  vec4 c2;  // Y22, Y3-3, Y3-2, Y3-1
  vec4 c3;  // Y30, Y31, Y32, Y33
};
MRGI_FN SH16 sh_basis16(vec3 d) {
  float x = d.x, y = d.y, z = d.z;
  float x2 = x * x, y2 = y * y, z2 = z * z;
  SH16 r;
  r.c0 = vec4(0.282094791773878f, -0.488602511902920f * y, 0.488602511902920f * z,
              -0.488602511902920f * x);
  r.c1 = vec4(1.092548430592079f * x * y, -1.092548430592079f * y * z,
              0.315391565252520f * (3.0f * z2 - 1.0f), -1.092548430592079f * x * z);
  r.c2 = vec4(0.546274215296040f * (x2 - y2), -0.590043589926644f * y * (3.0f * x2 - y2),
              2.890611442640554f * x * y * z, -0.457045799464466f * y * (5.0f * z2 - 1.0f));
  r.c3 = vec4(0.373176332590115f * z * (5.0f * z2 - 3.0f),
              -0.457045799464466f * x * (5.0f * z2 - 1.0f),
              1.445305721320277f * z * (x2 - y2), -0.590043589926644f * x * (x2 - 3.0f * y2));
  return r;
}
// Coefficient i (0..15) of an SH16; out-of-range i returns 0.
MRGI_FN float sh_get(SH16 s, int i) {
  vec4 v = i < 4 ? s.c0 : (i < 8 ? s.c1 : (i < 12 ? s.c2 : s.c3));
  int k = i - 4 * (i / 4);
  if (i < 0 || i > 15) return 0.0f;
  return k == 0 ? v.x : (k == 1 ? v.y : (k == 2 ? v.z : v.w));
}
MRGI_FN float sh_dot(SH16 a, SH16 b) {
  return dot(a.c0, b.c0) + dot(a.c1, b.c1) + dot(a.c2, b.c2) + dot(a.c3, b.c3);
}
// a + s b, coefficient by coefficient.
MRGI_FN SH16 sh_add_scaled(SH16 a, SH16 b, float s) {
  SH16 r;
  r.c0 = a.c0 + b.c0 * s;
  r.c1 = a.c1 + b.c1 * s;
  r.c2 = a.c2 + b.c2 * s;
  r.c3 = a.c3 + b.c3 * s;
  return r;
}

// The function `c` rotated by `r` (a rotation of directions): sh_dot(result, sh_basis16(d)) =
// sh_dot(c, sh_basis16(transpose(r) d)) for every unit d. Projected with a product quadrature
// exact for the product of two functions of bands <= 3 (degree 6): 4-point Gauss-Legendre in
// z = cos(theta) (exact to degree 7) times 7 equally spaced azimuths (exact for frequencies
// below 7), 28 points, so the rotation is exact to float rounding without per-band rotation
// matrices (which would need arrays, not allowed here). About 56 basis evaluations: meant for
// per-frame light (an environment estimate turned into the world frame), not per pixel.
MRGI_FN SH16 sh_rotate16(SH16 c, mat3 r) {
  SH16 acc;
  acc.c0 = vec4(0.0f);
  acc.c1 = vec4(0.0f);
  acc.c2 = vec4(0.0f);
  acc.c3 = vec4(0.0f);
  mat3 back = transpose(r);
  for (int i = 0; i < 4; ++i) {
    float z = i == 0 ? -0.861136311594053f : (i == 1 ? -0.339981043584856f : (i == 2 ? 0.339981043584856f : 0.861136311594053f));
    float w = (i == 0 || i == 3) ? 0.347854845137454f : 0.652145154862546f;
    float ring = sqrt(max(0.0f, 1.0f - z * z));
    for (int j = 0; j < 7; ++j) {
      float phi = 2.0f * MRGI_PI * (float(j) + 0.5f) / 7.0f;
      vec3 d = vec3(ring * cos(phi), ring * sin(phi), z);
      float value = sh_dot(c, sh_basis16(back * d));
      acc = sh_add_scaled(acc, sh_basis16(d), value * w * (2.0f * MRGI_PI / 7.0f));
    }
  }
  return acc;
}

// ---- importance sampling by hierarchical warping ----------------------------------------------

// One level of hierarchical sample warping (Clarberg, Jarosz, Akenine-Moeller and Jensen,
// "Wavelet Importance Sampling", 2005, Sec. 4): a sample u in [0, 1)^2 at a texel of a mip
// pyramid of importance picks one of its four children in proportion to their importance (q.x
// at (0, 0), q.y at (1, 0), q.z at (0, 1), q.w at (1, 1)): first the column by u.x, then the row
// in that column by u.y, and u is stretched back over [0, 1)^2 inside the child, so descending
// the pyramid lands on a leaf texel with probability importance / total, continuously in u (the
// warp keeps stratification: neighbouring u land on neighbouring texels). A zero-importance
// parent splits evenly. child: which child; probability: of that child given the parent.
struct WarpStep {
  vec2 u;
  ivec2 child;
  float probability;
};
MRGI_FN WarpStep warp_step(vec2 u, vec4 q) {
  q = max(q, vec4(0.0f));
  float total = q.x + q.y + q.z + q.w;
  if (!(total > 0.0f)) q = vec4(1.0f), total = 4.0f;
  WarpStep s;
  float p_left = (q.x + q.z) / total;
  int cx = u.x < p_left ? 0 : 1;
  float px = cx == 0 ? p_left : 1.0f - p_left;
  float ux = cx == 0 ? u.x / p_left : (u.x - p_left) / (1.0f - p_left);
  float top = cx == 0 ? q.x : q.y, bottom = cx == 0 ? q.z : q.w;
  float p_top = top + bottom > 0.0f ? top / (top + bottom) : 0.5f;
  int cy = u.y < p_top ? 0 : 1;
  float py = cy == 0 ? p_top : 1.0f - p_top;
  float uy = cy == 0 ? u.y / p_top : (u.y - p_top) / (1.0f - p_top);
  const float below_one = 0.99999994f;  // the largest float below 1
  s.u = vec2(clamp(ux, 0.0f, below_one), clamp(uy, 0.0f, below_one));
  s.child = ivec2(cx, cy);
  s.probability = px * py;
  return s;
}

// Zonal factors of the clamped-cosine kernel per band (Ramamoorthi & Hanrahan 2001):
// irradiance E(n) = sum_l A_l sum_m L_lm Y_lm(n); A = pi, 2pi/3, pi/4, 0 for l = 0..3.
MRGI_FN SH16 sh_scale_cosine_lobe(SH16 radiance) {
  SH16 r;
  const float a0 = MRGI_PI, a1 = 2.0f * MRGI_PI / 3.0f, a2 = MRGI_PI / 4.0f;
  r.c0 = radiance.c0 * vec4(a0, a1, a1, a1);
  r.c1 = radiance.c1 * vec4(a2, a2, a2, a2);
  r.c2 = radiance.c2 * vec4(a2, 0.0f, 0.0f, 0.0f);
  r.c3 = vec4(0.0f);
  return r;
}

// ---- lights ---------------------------------------------------------------------------------

// Spot cone: 1 inside the inner half-angle, 0 outside the outer one, smoothstep between, on
// the cosines. `cos_angle` = dot(spot direction, direction to the lit point).
MRGI_FN float spot_falloff(float cos_angle, float cos_outer, float cos_inner) {
  if (cos_inner <= cos_outer) return cos_angle >= cos_outer ? 1.0f : 0.0f;
  return smoothstep(cos_outer, cos_inner, cos_angle);
}

// ---- cameras --------------------------------------------------------------------------------

// Pinhole, OpenCV convention: x right, y down, looking along +z; `k` = (fx, fy, cx, cy) in
// pixels; integer pixel coordinates are pixel centres (pixel (0,0) covers [-0.5, 0.5]^2).
MRGI_FN vec2 project_pinhole(vec3 p_camera, vec4 k) {
  float iz = 1.0f / max(p_camera.z, 1e-9f);
  return vec2(k.x * p_camera.x * iz + k.z, k.y * p_camera.y * iz + k.w);
}
// The point at depth `z` (along +z, metres) seen at `pixel`.
MRGI_FN vec3 unproject_pinhole(vec2 pixel, float z, vec4 k) {
  return vec3((pixel.x - k.z) / k.x * z, (pixel.y - k.w) / k.y * z, z);
}

// ---- differential compose -------------------------------------------------------------------

// Knecht et al. (differential instant radiosity; "Reflective and Refractive Objects for Mixed
// Reality", eq. 1-2): L_final = CI + alpha * (L_rv - L_r), alpha = CI / L_r per channel, which
// makes the change relative to what the camera saw instead of to the model. Guards: where L_r
// is below `eps` the ratio is meaningless (dark or unmodelled real surface), so alpha blends to 1
// (absolute delta) over [eps, 2 eps]; alpha is clamped to [0, alpha_max]; the result is >= 0.
// Virtual pixels (virtual_mask = 1) show L_rv itself (the camera colour there is occluded).
// All inputs in the same (linear or camera) space.
MRGI_FN float compose_alpha1(float camera, float l_r, float eps, float alpha_max) {
  float ratio = clamp(camera / max(l_r, eps), 0.0f, alpha_max);
  return mix(1.0f, ratio, smoothstep(eps, 2.0f * eps, l_r));
}
MRGI_FN vec3 differential_compose(vec3 camera, vec3 l_r, vec3 l_rv, float virtual_mask,
                                  float eps, float alpha_max) {
  vec3 alpha = vec3(compose_alpha1(camera.x, l_r.x, eps, alpha_max),
                    compose_alpha1(camera.y, l_r.y, eps, alpha_max),
                    compose_alpha1(camera.z, l_r.z, eps, alpha_max));
  vec3 real = max(camera + alpha * (l_rv - l_r), vec3(0.0f));
  return mix(real, max(l_rv, vec3(0.0f)), clamp(virtual_mask, 0.0f, 1.0f));
}

// v with NaN and infinite channels replaced by 0.
MRGI_FN float finite1(float v) { return isnan(v) || isinf(v) ? 0.0f : v; }
MRGI_FN vec3 finite3(vec3 v) { return vec3(finite1(v.x), finite1(v.y), finite1(v.z)); }

// One output pixel of the composite, sRGB-encoded in [0, 1]: the solutions (linear radiance)
// seen by the camera model without its sRGB step (times the exposure, clipped to [0, 1]) are
// composed with the camera's linear value (differential_compose), and the result is encoded.
// Differences of sRGB-encoded values would darken shadows by the curve's slope, so the whole
// composite is linear (compose.comp says more). The solutions must be finite (callers
// sanitise them with finite3 where they read them: compose.comp per texel, before its bilinear
// mix); the result is, whatever they are. compose.comp runs it per output pixel; a technique
// that composes its own tiles (Technique::ComposeTiles::composed) runs the same function.
MRGI_FN vec3 compose_encoded(vec3 camera_linear, vec3 l_r, vec3 l_rv, float virtual_mask,
                             float exposure, float eps, float alpha_max) {
  vec3 tm_rv = clamp(l_rv * exposure, vec3(0.0f), vec3(1.0f));
  vec3 tm_r = clamp(l_r * exposure, vec3(0.0f), vec3(1.0f));
  vec3 out_linear = differential_compose(camera_linear, tm_r, tm_rv, virtual_mask, eps, alpha_max);
  return srgb_encode(clamp(finite3(out_linear), vec3(0.0f), vec3(1.0f)));
}

// One word of the composite's readback buffer: the sRGB-encoded colour (packUnorm4x8, r in the
// low byte) with the virtual-pixel mask in the alpha byte (255 virtual, 0 real); the host
// reads the mask from it and sets alpha to 255 (compose/compose.cpp Compose::read). One store
// a pixel instead of a colour and a mask word: on lavapipe the second store was a tenth of
// compose's time at 640x480.
MRGI_FN uint pack_output_word(vec3 encoded, bool is_virtual) {
  return packUnorm4x8(vec4(encoded, is_virtual ? 1.0f : 0.0f));
}

// Whether a real pixel whose tone-mapped solutions are tm_r, tm_rv (l * exposure clipped to
// [0, 1], as compose_encoded makes them) composes to the camera's 8-bit value within
// `tolerance` levels, for any camera value (compose's tile classifier, shaders/compose/
// tile_classify.comp). The composite moves the linear camera value c by alpha |tm_rv - tm_r|.
// Where tm_r >= 2 eps, alpha <= c / tm_r (the clamp at alpha_max only lowers it), so the move is
// at most c r with r = |d| / tm_r, and the sRGB-encoded value's at most 255 max(x srgb'(x)) r =
// 112.1 r (at x = 1: 1.055 / 2.4 x^(1 / 2.4); the linear segment's 12.92 x is smaller). Below
// 2 eps alpha <= alpha_max (>= 1), the move is at most alpha_max |d| in linear terms and the
// encoded value's at most 255 * 12.92 times that (the largest slope of the sRGB curve). A
// bilinear mix of such texels (positive weights) stays within the largest of their bounds.
MRGI_FN bool compose_channel_invisible(float tm_r, float tm_rv, float eps, float alpha_max, float tolerance) {
  float d = abs(tm_rv - tm_r);
  if (tm_r >= 2.0f * eps) return 112.1f * d <= tolerance * tm_r;
  return 255.0f * 12.92f * max(alpha_max, 1.0f) * d <= tolerance;
}
MRGI_FN bool compose_tile_invisible(vec3 tm_r, vec3 tm_rv, float eps, float alpha_max, float tolerance) {
  return compose_channel_invisible(tm_r.x, tm_rv.x, eps, alpha_max, tolerance) &&
         compose_channel_invisible(tm_r.y, tm_rv.y, eps, alpha_max, tolerance) &&
         compose_channel_invisible(tm_r.z, tm_rv.z, eps, alpha_max, tolerance);
}

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef MRGI_FN
#endif

#endif  // MRGI_SHARED_H
