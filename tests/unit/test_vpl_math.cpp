// The VPL and paraboloid-map math (shaders/shared/vpl_math.h) on the CPU: the same functions
// the VPL, ISM and dir shaders run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "shared/vpl_math.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

TEST(VplMath, HaltonIsTheRadicalInverse) {
  EXPECT_FLOAT_EQ(halton(0, 2), 0.0f);
  EXPECT_FLOAT_EQ(halton(1, 2), 0.5f);
  EXPECT_FLOAT_EQ(halton(2, 2), 0.25f);
  EXPECT_FLOAT_EQ(halton(3, 2), 0.75f);
  EXPECT_FLOAT_EQ(halton(1, 3), 1.0f / 3.0f);
  EXPECT_FLOAT_EQ(halton(5, 3), 7.0f / 9.0f);  // 5 = 12 in base 3 -> 0.21 = 2/3 + 1/9
  // Stratified: the first 2^k values of base 2 hit every interval of width 2^-k once.
  int hits[16] = {};
  for (uint i = 0; i < 16; ++i) ++hits[int(halton(i, 2) * 16.0f)];
  for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(VplMath, TangentFrameIsOrthonormalForEveryNormal) {
  for (int k = 0; k < 200; ++k) {
    const double y = 1.0 - 2.0 * (k + 0.5) / 200, r = std::sqrt(1.0 - y * y), phi = 2.39996 * k;
    const vec3 n(float(r * std::cos(phi)), float(r * std::sin(phi)), float(y));
    const vec3 t = frame_tangent(n), b = frame_bitangent(n);
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(b), 1.0f, 1e-5f);
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(glm::cross(t, b), n), 1.0f, 1e-5f);  // right-handed
  }
}

TEST(VplMath, ParaboloidMapsTheHemisphereOntoTheDiskAndBack) {
  const vec3 n = glm::normalize(vec3(0.3f, -0.5f, 0.8f));
  EXPECT_NEAR(glm::length(paraboloid_uv(n, n)), 0.0f, 1e-6f);  // the normal: the centre
  for (int k = 0; k < 100; ++k) {
    const vec2 uv(0.9f * float(std::cos(k * 0.7)) * float(k) / 100.0f, 0.9f * float(std::sin(k * 0.7)) * float(k) / 100.0f);
    const vec3 w = paraboloid_direction(uv, n);
    EXPECT_NEAR(glm::length(w), 1.0f, 1e-5f);
    EXPECT_GE(dot(w, n), -1e-6f);
    const vec2 back = paraboloid_uv(w, n);
    EXPECT_NEAR(back.x, uv.x, 1e-5f);
    EXPECT_NEAR(back.y, uv.y, 1e-5f);
  }
  EXPECT_EQ(paraboloid_uv(-n, n), vec2(2.0f));  // behind: outside the disk
}

TEST(VplMath, ParaboloidTexelsTileTheHemisphere) {
  // The texels inside the disk sum to the hemisphere's 2 pi sr.
  const int size = 256;
  double sum = 0.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const vec2 uv((x + 0.5f) / size * 2.0f - 1.0f, (y + 0.5f) / size * 2.0f - 1.0f);
      if (dot(uv, uv) <= 1.0f) sum += paraboloid_texel_solid_angle(uv, float(size));
    }
  EXPECT_NEAR(sum, 2.0 * kPi, 0.01 * 2.0 * kPi);
}

TEST(VplMath, IrradianceIsACosineEmitterOverDistanceSquared) {
  // Straight above, facing each other, 2 m: E = P / pi / 4.
  const vec3 q(0.0f), nq(0.0f, 1.0f, 0.0f), p(0.0f, 2.0f, 0.0f), np(0.0f, -1.0f, 0.0f);
  EXPECT_NEAR(vpl_irradiance(p, np, q, nq, 10.0f, 0.01f), 10.0 / kPi / 4.0, 1e-5);
  // 60 degrees off the VPL's normal, receiver facing it: a factor cos 60 = 0.5.
  const vec3 w(std::sin(kPi / 3), std::cos(kPi / 3), 0.0f);
  EXPECT_NEAR(vpl_irradiance(2.0f * w, -w, q, nq, 10.0f, 0.01f), 0.5 * 10.0 / kPi / 4.0, 1e-5);
  // Behind the VPL or facing away: nothing.
  EXPECT_EQ(vpl_irradiance(vec3(0.0f, -2.0f, 0.0f), nq, q, nq, 10.0f, 0.01f), 0.0f);
  EXPECT_EQ(vpl_irradiance(p, -np, q, nq, 10.0f, 0.01f), 0.0f);
  // Bounded next to it: at 1 mm with a 0.1 m clamp, as at 0.1 m.
  EXPECT_NEAR(vpl_irradiance(vec3(0.0f, 0.001f, 0.0f), np, q, nq, 1.0f, 0.1f), 1.0 / kPi / 0.01, 1e-3);
  EXPECT_EQ(vpl_irradiance(q, np, q, nq, 1.0f, 0.1f), 0.0f);  // on it: 0, not NaN
}

// The hemisphere integral of a VPL's intensity (vpl_intensity), W: the flux it reflects.
double emitted(vec3 n, vec3 flux, vec4 lobe, vec4 specular, vec3* peak = nullptr) {
  constexpr int kTheta = 400, kPhi = 800;
  double sum = 0.0, best = -1.0;
  for (int i = 0; i < kTheta; ++i) {
    const double t = (i + 0.5) / kTheta * kPi / 2, st = std::sin(t);
    for (int j = 0; j < kPhi; ++j) {
      const double p = (j + 0.5) / kPhi * 2 * kPi;
      const vec3 w(float(st * std::cos(p)), float(std::cos(t)), float(st * std::sin(p)));  // n = +y
      const double v = double(vpl_intensity(n, w, flux, lobe, specular).x);
      sum += v * st * (kPi / 2 / kTheta) * (2 * kPi / kPhi);
      if (peak && v > best) {
        best = v;
        *peak = w;
      }
    }
  }
  return sum;
}

TEST(VplMath, ALobeFreeVplIsTheCosineEmitter) {
  const vec3 n(0.0f, 1.0f, 0.0f), w = normalize(vec3(0.3f, 0.8f, -0.2f));
  const vec4 none(0.0f, 0.0f, 1.0f, -1.0f);
  EXPECT_NEAR(vpl_intensity(n, w, vec3(2.0f), none, vec4(5.0f)).x, 2.0 / kPi * double(w.y), 1e-6);
  EXPECT_NEAR(emitted(n, vec3(2.0f), none, vec4(0.0f)), 2.0, 2e-3);
  // vpl_irradiance_rgb without a lobe is vpl_irradiance.
  const vec3 q(0.0f), p(0.4f, 1.0f, 0.2f), np = normalize(vec3(0.1f, -1.0f, 0.0f));
  EXPECT_NEAR(vpl_irradiance_rgb(p, np, q, n, vec3(3.0f), none, vec4(0.0f), 0.01f).x,
              vpl_irradiance(p, np, q, n, 3.0f, 0.01f), 1e-6);
}

TEST(VplMath, AGlossyVplReflectsItsLightAroundTheMirrorDirectionWithoutGainingEnergy) {
  const vec3 n(0.0f, 1.0f, 0.0f);
  const vec3 in = normalize(vec3(-0.5f, 1.0f, 0.0f));  // where its light came from: 27 degrees off n
  const vec3 mirror = normalize(vec3(0.5f, 1.0f, 0.0f));
  for (float roughness : {0.3f, 0.5f, 0.8f}) {
    // A white metal: all of Phi_in = 1 W in the lobe.
    vec3 peak(0.0f);
    const double lobe = emitted(n, vec3(0.0f), vec4(in, roughness), vec4(1.0f), &peak);
    std::printf("roughness %.1f: lobe reflects %.3f of the light\n", roughness, lobe);
    // GGX with a single scattering loses the light of its multiple scattering: the rougher, the
    // more (Kulla and Conty 2017; measured here 0.99, 0.91, 0.56 of the light at 0.3, 0.5, 0.8).
    EXPECT_LE(lobe, 1.01) << roughness;
    EXPECT_GE(lobe, roughness < 0.6f ? 0.85 : 0.5) << roughness;
    // The lobe's peak: at the mirror direction, pulled towards n by the cosine as it widens.
    const double off = std::acos(std::min(1.0, double(dot(peak, mirror)))) * 180.0 / kPi;
    EXPECT_LT(off, roughness < 0.4f ? 4.0 : 15.0) << roughness;
    EXPECT_NEAR(peak.z, 0.0f, 0.02f) << "in the plane of incidence";
  }
  // A dielectric (base 0.8, metallic 0): the split keeps (1 - F0) of the diffuse light and F0 in
  // the lobe; together no more than the base colour's share.
  const VplGlossySplit s = vpl_glossy_split(vec3(1.0f), vec3(0.8f), 0.0f);
  EXPECT_NEAR(s.diffuse_flux.x, 0.8 * 0.96, 1e-6);
  EXPECT_NEAR(s.specular_flux.x, 0.04, 1e-6);
  EXPECT_NEAR(s.incident_luminance, 1.0, 1e-5);
  const double total = emitted(n, s.diffuse_flux, vec4(in, 0.5f), vec4(s.specular_flux, s.incident_luminance));
  EXPECT_GT(total, 0.78);
  EXPECT_LT(total, 0.84);
  // The lobe never narrows below MRGI_VPL_MIN_ROUGHNESS: a mirror's VPL is a finite lobe.
  EXPECT_NEAR(emitted(n, vec3(0.0f), vec4(in, 0.0f), vec4(1.0f)), emitted(n, vec3(0.0f), vec4(in, MRGI_VPL_MIN_ROUGHNESS), vec4(1.0f)), 1e-9);
  // Light arriving from behind the surface reflects nothing.
  EXPECT_EQ(emitted(n, vec3(0.0f), vec4(-in, 0.5f), vec4(1.0f)), 0.0);
}

}  // namespace
