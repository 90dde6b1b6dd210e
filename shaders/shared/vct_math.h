// Voxel cone tracing math of Delta Voxel Cone Tracing (Thoener & Kuijper, "Delta global
// illumination for mixed reality", ../shared/papers/delta-voxel-cone-tracing.md; cone tracing
// after Crassin et al. 2011), shared by the dvct shaders and the C++ tests under the rules of
// mrgi_shared.h. Distances are in voxels of the volume's finest level unless a name says metres.
//
//   - A cone samples the volume's mip chain at increasing distance; a sample's footprint is the
//     cone's diameter there, its mip level log2(diameter / voxel) (Sec. 3.1, Fig. 1 b).
//   - Steps follow the footprint "at that and the next step ... to avoid reading from
//     overlapping voxels" (Sec. 3.1): the next sample's ball touches this one's,
//     d' - d = (D(d) + D(d')) / 2 with D(d) = r d, i.e. d' = d (1 + r/2) / (1 - r/2).
//   - Light and occlusion accumulate front to back (vct_accumulate; where it departs from the
//     paper's printed formula, and why, is said there), the occlusion a voxel reads adapted by
//     the normal it stores (vct_directional_occlusion).
//   - Diffuse light: a fixed set of wide cones over the hemisphere, weighted by the cosine
//     (vct_diffuse_cone); specular: one cone around the mirror direction whose aperture follows
//     the GGX lobe's width (vct_specular_aperture); shadows: one cone to each lamp (Sec. 3.5).
#ifndef MRGI_VCT_MATH_H
#define MRGI_VCT_MATH_H

#include "shared/mrgi_shared.h"

#ifdef __cplusplus
namespace mrgi::shader {
#define MRGI_FN inline
#else
#define MRGI_FN
#endif

// The widest cone the step rule takes: r = 2 tan(aperture / 2) < 2, i.e. an aperture under 90
// degrees (wider cones would need the next sample infinitely far to not overlap this one).
const float VCT_MAX_DIAMETER_RATIO = 1.8f;

// Diameter-to-distance ratio of a cone of full aperture `aperture` (radians).
MRGI_FN float vct_diameter_ratio(float aperture) {
  return min(2.0f * tan(0.5f * aperture), VCT_MAX_DIAMETER_RATIO);
}

// The sample footprint at distance d (voxels): the cone's diameter, never under `min_diameter`
// (half a voxel: a narrower sample would read between voxels of the finest level).
MRGI_FN float vct_diameter(float ratio, float d, float min_diameter) { return max(min_diameter, ratio * d); }

// The mip level a footprint of `diameter` voxels reads (0 = the finest), clamped to the chain.
MRGI_FN float vct_lod(float diameter, float max_lod) { return clamp(log2(max(diameter, 1.0f)), 0.0f, max_lod); }

// The distance of the next sample after one at d: its footprint and this one's touch (above).
// Below the footprint's floor the two are min_diameter apart.
MRGI_FN float vct_next_distance(float ratio, float d, float min_diameter) {
  const float cone = d * (1.0f + 0.5f * ratio) / (1.0f - 0.5f * ratio);
  return max(cone, d + min_diameter);
}

// The step actually taken: `step_scale` (0, 1] of the touching-footprint step above. At 1 it is
// the paper's rule; a cone that meets a surface one voxel thick then reads it at one sample
// whose footprint may straddle it, interpolated with the empty space beside it, so what it
// gathers depends on where the samples fall (aliasing: a 1.2 rad cone at a lit one-voxel wall
// gathered 0.57 of its light, and 1.00 or 0.62 at a half or a third of the step). Denser
// samples with the opacity corrected for the shorter step (vct_opacity_for_step) converge on
// the footprint's true coverage instead (tests/gi/test_vct_trace.cpp measures both).
MRGI_FN float vct_step(float ratio, float d, float min_diameter, float step_scale) {
  return d + clamp(step_scale, 0.05f, 1.0f) * (vct_next_distance(ratio, d, min_diameter) - d);
}

// Opacity correction for a step of `step_scale` of the touching step: a sample stands for that
// fraction of its footprint's depth, so its occlusion a becomes 1 - (1 - a)^step_scale (the
// transmittance of the shorter segment of the same medium); 1 keeps a.
MRGI_FN float vct_opacity_for_step(float occlusion, float step_scale) {
  const float a = clamp(occlusion, 0.0f, 1.0f);
  return a >= 1.0f ? 1.0f : 1.0f - pow(1.0f - a, clamp(step_scale, 0.05f, 1.0f));
}

// A sample's light (vct_sample's rgb, which goes with its occlusion a) for the shorter step:
// scaled as its occlusion is, so light and occlusion stay in the ratio the voxel holds.
MRGI_FN vec3 vct_light_for_step(vec4 sample_light_occlusion, float step_scale) {
  const float a = sample_light_occlusion.w;
  const float k = a > 1e-6f ? vct_opacity_for_step(a, step_scale) / a : 0.0f;
  return vec3(sample_light_occlusion.x, sample_light_occlusion.y, sample_light_occlusion.z) * k;
}

// Front-to-back accumulation (Sec. 3.1). acc: rgb the light gathered, a the occlusion; the
// sample: `light` its pre-multiplied light (what the voxel's surfaces send, already weighted by
// how much of the voxel they cover), `occlusion` in [0, 1].
//   occlusion_acc' = occlusion_acc + occlusion (1 - occlusion_acc)     (the paper's)
//   light_acc'     = light_acc + light (1 - occlusion_acc)
// The paper prints light_acc' = light_acc occlusion_acc + light occlusion (1 - occlusion_acc).
// Taken literally, light gathered by a half-occluding sample halves again at every empty sample
// after it (occlusion_acc = 0.5 scales it each step), so a cone's light would depend on how far
// it runs past the surface; and light would be weighted by occlusion twice where the volume
// already holds it pre-multiplied (the injection averages light over a voxel as the mip chain
// averages occlusion). The form here is the emission-absorption compositing of Crassin et al.
// that the paper cites as its method ([8]); vct_math_test shows both on the same samples.
MRGI_FN vec4 vct_accumulate(vec4 acc, vec3 light, float occlusion) {
  const float transmit = 1.0f - acc.w;
  return vec4(acc.x + light.x * transmit, acc.y + light.y * transmit, acc.z + light.z * transmit,
              acc.w + clamp(occlusion, 0.0f, 1.0f) * transmit);
}

// "The occlusion value is thereby adapted with the normal that is stored in the volume"
// (Sec. 3.1). A visibility voxel stores (n, o): o the fraction of it holding geometry, n the mean
// of its surfaces' unit normals times o (premultiplied, so the mip chain's plain mean keeps both
// right: gi/volume_downsample.comp). |n| / o near 1 is one flat surface, near 0 surfaces facing
// every way. Two adaptations, both by how coherent the surfaces are:
//   - coverage: at mip level `lod` a voxel spans 2^lod finest voxels a side, and a flat surface
//     crossing it fills only one finest voxel in 2^lod of each column, so o = 2^-lod for a
//     surface that covers the whole footprint. Its coverage is min(1, o 2^lod); surfaces facing
//     every way (clutter filling the voxel) cover o. Without this a one-voxel wall would be half
//     transparent at level 1, a quarter at level 2: light through real geometry, which Sec. 3.2's
//     separate visibility volumes are there to prevent;
//   - direction: a small flat patch covers the fraction |n . dir| of the footprint's
//     cross-section (edge-on it hides nothing), clutter the same from every side.
// So: coverage x mix(1, |n^ . dir|, coherence), the direction factor never below
// `floor_fraction` (a surface exactly edge-on still has thickness: reconstruction noise).
MRGI_FN float vct_directional_occlusion(vec4 normal_occlusion, vec3 dir, float floor_fraction, float lod) {
  const float o = clamp(normal_occlusion.w, 0.0f, 1.0f);
  if (o <= 0.0f) return 0.0f;
  const vec3 n = vec3(normal_occlusion.x, normal_occlusion.y, normal_occlusion.z);
  const float len = length(n);
  const float coherence = min(len / o, 1.0f);
  const float facing = len > 1e-6f ? abs(dot(n, dir)) / len : 1.0f;
  const float coverage = mix(o, min(1.0f, o * exp2(lod)), coherence);
  return coverage * max(mix(1.0f, facing, coherence), floor_fraction);
}

// What one cone sample adds (vct_accumulate's light and occlusion) from the two volumes' values
// at its footprint: `light` the light volume's rgb (radiance x coverage, gi/voxel_light.h),
// `visibility` the visibility volume's (mean normal x occupancy, occupancy), both read at mip
// level `lod`. The light is radiance x occupancy, so the light seen is the radiance times the
// coverage the occlusion says (vct_directional_occlusion), and a coherent surface seen from behind sends nothing towards the cone (its
// light leaves its front; a thin real surface's back is another surface the reconstruction did
// not see). rgb: light, a: occlusion.
MRGI_FN vec4 vct_sample(vec3 light, vec4 visibility, vec3 dir, float floor_fraction, float lod) {
  const float o = clamp(visibility.w, 0.0f, 1.0f);
  const float occ = vct_directional_occlusion(visibility, dir, floor_fraction, lod);
  if (o <= 0.0f) return vec4(0.0f);
  const vec3 n = vec3(visibility.x, visibility.y, visibility.z);
  const float coherence = min(length(n) / o, 1.0f);
  // -dir points from the sample back to the cone's apex: a front face has n . -dir > 0.
  const float front = dot(n, dir) < 0.0f ? 1.0f : 1.0f - coherence;
  const float seen = occ / o * front;
  return vec4(light.x * seen, light.y * seen, light.z * seen, occ);
}

// The diffuse cone set: VCT_DIFFUSE_MAX cones at most, `count` used (1, 5 or 9 and more): one
// along the normal, the rest in one ring (count <= 7) or two rings (the inner with a third of
// them), each cone's aperture covering its share of the hemisphere. A cone of tangent-space
// direction (x, y, z), z along the normal.
const int VCT_DIFFUSE_MAX = 16;
struct VctCone {
  vec3 dir;        // tangent space, z = the normal
  float aperture;  // full aperture, radians
  float weight;    // irradiance = sum weight x the cone's mean radiance (sum of weights = pi)
};

// Polar angle of the ring a cone sits in, and the ring's size, for cone `i` of `count`.
MRGI_FN vec2 vct_ring_of(int i, int count) {
  // (polar angle, azimuth) of cone i >= 1.
  const int around = count - 1;
  const int inner = around > 6 ? around / 3 : 0;
  const float golden = 2.39996323f;  // azimuths of the two rings interleave
  if (i <= inner) return vec2(0.5236f, 2.0f * MRGI_PI * float(i - 1) / float(max(inner, 1)));
  const int k = i - 1 - inner;
  const float polar = inner > 0 ? 1.1345f : 0.9553f;  // 65 degrees, or 54.7 with one ring
  return vec2(polar, 2.0f * MRGI_PI * float(k) / float(around - inner) + (inner > 0 ? golden : 0.0f));
}

// Cone i of a set of `count` (1 <= count <= VCT_DIFFUSE_MAX). The weights are the cosine of
// each cone's axis times its solid angle, normalised so that a uniform radiance L gives
// irradiance pi L (what the hemisphere integral of L cos gives).
MRGI_FN VctCone vct_diffuse_cone(int i, int count) {
  VctCone c;
  const int n = clamp(count, 1, VCT_DIFFUSE_MAX);
  // Each cone's share of the hemisphere's 2 pi sr as a cap: 2 pi (1 - cos(a/2)) = 2 pi / n.
  const float half_angle = acos(max(1.0f - 1.0f / float(n), 0.0f));
  c.aperture = min(2.0f * half_angle, 2.0f * atan(0.5f * VCT_MAX_DIAMETER_RATIO));
  float polar = 0.0f, azimuth = 0.0f;
  if (i > 0) {
    const vec2 ring = vct_ring_of(i, n);
    polar = ring.x;
    azimuth = ring.y;
  }
  c.dir = vec3(sin(polar) * cos(azimuth), sin(polar) * sin(azimuth), cos(polar));
  // Normalisation over the set: sum over cones of cos(polar).
  float sum_cos = 1.0f;
  for (int k = 1; k < n; ++k) sum_cos += cos(vct_ring_of(k, n).x);
  c.weight = MRGI_PI * cos(polar) / sum_cos;
  return c;
}

// The specular cone's full aperture for GGX roughness `roughness` (perceptual; alpha =
// roughness^2): the reflected lobe's half-power width. GGX's D falls to half its peak where
// tan^2(theta_h) = alpha^2 (sqrt(2) - 1) for the half vector, and the reflected direction turns
// twice as far, so the cone's half-angle is 2 atan(0.6436 alpha). Clamped to [min_aperture, the
// widest the step rule takes]: roughness 0 is a mirror, traced as narrow as the volume resolves.
MRGI_FN float vct_specular_aperture(float roughness, float min_aperture) {
  const float alpha = roughness * roughness;
  const float half_angle = 2.0f * atan(0.6436f * alpha);
  return clamp(2.0f * half_angle, min_aperture, 2.0f * atan(0.5f * VCT_MAX_DIAMETER_RATIO));
}

// What a specular cone's radiance is weighted by: the GGX lobe's directional albedo for
// reflectance f0 at n.v and roughness, from Karis' analytic fit of the split-sum table
// ("Physically based shading on mobile", 2014), so a cone's mean radiance times this is the
// reflected radiance without a lookup table bound in every shading pass. In [0, 1] per channel
// for f0 in [0, 1].
MRGI_FN vec3 vct_specular_weight(vec3 f0, float roughness, float n_dot_v) {
  const float r = clamp(roughness, 0.0f, 1.0f);
  const vec4 rr = vec4(-1.0f, -0.0275f, -0.572f, 0.022f) * r + vec4(1.0f, 0.0425f, 1.04f, -0.04f);
  const float a004 = min(rr.x * rr.x, exp2(-9.28f * max(n_dot_v, 0.0f))) * rr.x + rr.y;
  const float scale = -1.04f * a004 + rr.z, bias = 1.04f * a004 + rr.w;
  return clamp(f0 * scale + vec3(bias), vec3(0.0f), vec3(1.0f));
}

#ifdef __cplusplus
}  // namespace mrgi::shader
#undef MRGI_FN
#endif

#endif  // MRGI_VCT_MATH_H
