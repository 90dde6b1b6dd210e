// CPU checks of shaders/shared/mrgi_shared.h, the math the shaders run: known values, round
// trips, and SH orthonormality by numeric integration over the sphere.
#include <gtest/gtest.h>

#include <limits>

#include <cmath>
#include <random>
#include <vector>

#include "../../shaders/shared/mrgi_shared.h"

namespace {
using namespace mrgi::shader;

TEST(SharedMath, SrgbKnownValues) {
  EXPECT_FLOAT_EQ(srgb_encode1(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgb_encode1(1.0f), 1.0f);
  EXPECT_NEAR(srgb_encode1(0.5f), 0.735357f, 1e-5f);       // 188/255 in 8 bit
  EXPECT_NEAR(srgb_encode1(0.002f), 0.002f * 12.92f, 1e-7f);  // linear toe
  EXPECT_NEAR(srgb_decode1(0.5f), 0.214041f, 1e-5f);
  EXPECT_FLOAT_EQ(srgb_encode1(7.0f), 1.0f);                // clipped, not extrapolated
  EXPECT_FLOAT_EQ(srgb_encode1(-1.0f), 0.0f);
  // Continuity at the toe/curve boundary.
  EXPECT_NEAR(srgb_encode1(0.0031308f), srgb_encode1(0.0031309f), 1e-5f);
  EXPECT_NEAR(srgb_decode1(0.04045f), srgb_decode1(0.040451f), 1e-5f);
}

TEST(SharedMath, SrgbRoundTripEvery8BitValue) {
  for (int i = 0; i <= 255; ++i) {
    const float e = float(i) / 255.0f;
    EXPECT_NEAR(srgb_encode1(srgb_decode1(e)), e, 2e-6f) << i;
  }
  const vec3 v = srgb_decode(srgb_encode(vec3(0.1f, 0.5f, 0.9f)));
  EXPECT_NEAR(v.x, 0.1f, 1e-5f);
  EXPECT_NEAR(v.y, 0.5f, 1e-5f);
  EXPECT_NEAR(v.z, 0.9f, 1e-5f);
}

TEST(SharedMath, LuminanceWeights) {
  EXPECT_NEAR(luminance(vec3(1.0f)), 1.0f, 1e-6f);
  EXPECT_NEAR(luminance(vec3(0.0f, 1.0f, 0.0f)), 0.7152f, 1e-6f);
  EXPECT_GT(luminance(vec3(0.0f, 1.0f, 0.0f)), luminance(vec3(1.0f, 0.0f, 0.0f)));
}

TEST(SharedMath, CameraResponseAndInverse) {
  // exposure 0.5: radiance 1 -> linear 0.5 -> sRGB 0.7354.
  EXPECT_NEAR(camera_response(vec3(1.0f), 0.5f).x, 0.735357f, 1e-5f);
  // saturates at 1
  EXPECT_FLOAT_EQ(camera_response(vec3(10.0f), 1.0f).y, 1.0f);
  const vec3 r = camera_to_radiance(camera_response(vec3(0.3f, 0.6f, 1.2f), 0.7f), 0.7f);
  EXPECT_NEAR(r.x, 0.3f, 1e-5f);
  EXPECT_NEAR(r.y, 0.6f, 1e-5f);
  EXPECT_NEAR(r.z, 1.2f, 1e-5f);
  // A zero exposure must not divide by zero.
  EXPECT_TRUE(std::isfinite(camera_to_radiance(vec3(0.5f), 0.0f).x));
}

TEST(SharedMath, OctahedralRoundTrip) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  float worst = 0.0f;
  for (int i = 0; i < 20000; ++i) {
    const vec3 n = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    const vec2 e = oct_encode(n);
    ASSERT_LE(std::abs(e.x), 1.0f + 1e-6f);
    ASSERT_LE(std::abs(e.y), 1.0f + 1e-6f);
    const vec3 d = oct_decode(e);
    worst = std::max(worst, glm::length(d - n));
    // Packed to 2 x snorm16: error below 1e-4 rad-ish.
    EXPECT_LT(glm::length(oct_unpack(oct_pack(n)) - n), 1e-4f);
  }
  EXPECT_LT(worst, 1e-5f);
  // Axis and seam cases, including -z where the fold happens.
  for (vec3 n : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, -1, 0),
                 glm::normalize(vec3(1, 1, -1)), glm::normalize(vec3(-1, 0, -1))}) {
    EXPECT_LT(glm::length(oct_decode(oct_encode(n)) - n), 1e-5f);
  }
}

TEST(SharedMath, ShKnownValues) {
  const SH16 z = sh_basis16(vec3(0, 0, 1));
  EXPECT_NEAR(z.c0.x, 0.5f / std::sqrt(float(M_PI)), 1e-6f);
  EXPECT_NEAR(z.c0.z, std::sqrt(3.0f / (4.0f * float(M_PI))), 1e-6f);
  EXPECT_NEAR(z.c1.z, std::sqrt(5.0f / (16.0f * float(M_PI))) * 2.0f, 1e-6f);  // 3z^2-1 = 2
  EXPECT_NEAR(z.c3.x, std::sqrt(7.0f / (16.0f * float(M_PI))) * 2.0f, 1e-5f);  // z(5z^2-3) = 2
  // Sloan's sign convention: Y1,1 = -c x.
  const SH16 x = sh_basis16(vec3(1, 0, 0));
  EXPECT_LT(x.c0.w, 0.0f);
  EXPECT_NEAR(x.c0.w, -0.488603f, 1e-5f);
  EXPECT_FLOAT_EQ(sh_get(x, 3), x.c0.w);
  EXPECT_FLOAT_EQ(sh_get(x, 15), x.c3.w);
  EXPECT_FLOAT_EQ(sh_get(x, 16), 0.0f);
  EXPECT_FLOAT_EQ(sh_get(x, -1), 0.0f);
}

// Integral over the sphere of Y_i Y_j = delta_ij, by a midpoint rule in (cos theta, phi), which is
// uniform in solid angle.
TEST(SharedMath, ShOrthonormalByIntegration) {
  const int nu = 256, nphi = 512;
  double gram[16][16] = {};
  const double dw = (2.0 / nu) * (2.0 * M_PI / nphi);
  for (int i = 0; i < nu; ++i) {
    const double u = -1.0 + (i + 0.5) * 2.0 / nu;
    const double s = std::sqrt(1.0 - u * u);
    for (int j = 0; j < nphi; ++j) {
      const double phi = (j + 0.5) * 2.0 * M_PI / nphi;
      const SH16 y = sh_basis16(vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(u)));
      for (int a = 0; a < 16; ++a)
        for (int b = a; b < 16; ++b) gram[a][b] += double(sh_get(y, a)) * sh_get(y, b) * dw;
    }
  }
  for (int a = 0; a < 16; ++a)
    for (int b = a; b < 16; ++b) EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-3) << a << "," << b;
}

// Irradiance of a constant radiance L over the hemisphere is pi L; of a single-direction lobe it
// follows the clamped cosine.
TEST(SharedMath, ShCosineLobeGivesIrradiance) {
  SH16 radiance{};
  radiance.c0 = vec4(1.0f / 0.282094791773878f, 0, 0, 0);  // constant radiance 1
  const SH16 e = sh_scale_cosine_lobe(radiance);
  EXPECT_NEAR(sh_dot(e, sh_basis16(vec3(0, 1, 0))), float(M_PI), 1e-4f);
  // Project a narrow lobe from +z and check E(n) ~ max(cos, 0) shape at a few normals.
  const vec3 light = vec3(0, 0, 1);
  SH16 proj = sh_basis16(light);  // delta function of unit intensity in direction `light`
  const SH16 irr = sh_scale_cosine_lobe(proj);
  const float e_up = sh_dot(irr, sh_basis16(light));
  const float e_side = sh_dot(irr, sh_basis16(vec3(1, 0, 0)));
  const float e_down = sh_dot(irr, sh_basis16(vec3(0, 0, -1)));
  EXPECT_NEAR(e_up, 1.0f, 0.1f);  // band-limited approximation of cos(0) = 1
  EXPECT_LT(std::abs(e_side), 0.2f);
  EXPECT_LT(std::abs(e_down), 0.1f);
}

TEST(SharedMath, SpotFalloff) {
  const float co = std::cos(glm::radians(30.0f)), ci = std::cos(glm::radians(20.0f));
  EXPECT_FLOAT_EQ(spot_falloff(1.0f, co, ci), 1.0f);
  EXPECT_FLOAT_EQ(spot_falloff(ci, co, ci), 1.0f);
  EXPECT_FLOAT_EQ(spot_falloff(co, co, ci), 0.0f);
  EXPECT_FLOAT_EQ(spot_falloff(std::cos(glm::radians(45.0f)), co, ci), 0.0f);
  const float mid = spot_falloff(0.5f * (co + ci), co, ci);
  EXPECT_NEAR(mid, 0.5f, 1e-5f);
  // Monotonic inside the transition.
  float prev = -1.0f;
  for (int i = 0; i <= 10; ++i) {
    const float v = spot_falloff(co + (ci - co) * float(i) / 10.0f, co, ci);
    EXPECT_GE(v, prev);
    prev = v;
  }
  // Degenerate cone (inner == outer) is a hard edge, not NaN.
  EXPECT_FLOAT_EQ(spot_falloff(0.95f, 0.9f, 0.9f), 1.0f);
  EXPECT_FLOAT_EQ(spot_falloff(0.85f, 0.9f, 0.9f), 0.0f);
}

TEST(SharedMath, PinholeProjectUnproject) {
  const vec4 k(517.3f, 516.5f, 318.6f, 255.3f);
  // The principal point sees the optical axis.
  const vec2 c = project_pinhole(vec3(0, 0, 2), k);
  EXPECT_FLOAT_EQ(c.x, 318.6f);
  EXPECT_FLOAT_EQ(c.y, 255.3f);
  // +x right, +y down in the image (OpenCV).
  const vec2 p = project_pinhole(vec3(0.1f, 0.2f, 1.0f), k);
  EXPECT_NEAR(p.x, 318.6f + 51.73f, 1e-3f);
  EXPECT_NEAR(p.y, 255.3f + 103.3f, 1e-3f);
  for (vec3 q : {vec3(0.3f, -0.2f, 1.5f), vec3(-1.0f, 0.7f, 4.0f)}) {
    const vec3 r = unproject_pinhole(project_pinhole(q, k), q.z, k);
    EXPECT_NEAR(r.x, q.x, 1e-5f);
    EXPECT_NEAR(r.y, q.y, 1e-5f);
    EXPECT_NEAR(r.z, q.z, 1e-6f);
  }
  // Behind the camera or at z = 0: finite, never NaN.
  const vec2 z0 = project_pinhole(vec3(1, 1, 0), k);
  EXPECT_TRUE(std::isfinite(z0.x) && std::isfinite(z0.y));
}

TEST(SharedMath, DifferentialCompose) {
  const float eps = 1e-3f, amax = 4.0f;
  // No change between L_r and L_rv -> the camera image untouched.
  vec3 o = differential_compose(vec3(0.4f, 0.5f, 0.6f), vec3(0.2f), vec3(0.2f), 0.0f, eps, amax);
  EXPECT_NEAR(o.x, 0.4f, 1e-6f);
  EXPECT_NEAR(o.z, 0.6f, 1e-6f);
  // A virtual shadow halving the modelled light halves the camera colour (alpha = CI / L_r).
  o = differential_compose(vec3(0.4f), vec3(0.8f), vec3(0.4f), 0.0f, eps, amax);
  EXPECT_NEAR(o.x, 0.2f, 1e-6f);
  // Where L_r -> 0 (unlit in the model) the delta is added as is (alpha -> 1), finite.
  o = differential_compose(vec3(0.3f), vec3(0.0f), vec3(0.25f), 0.0f, eps, amax);
  EXPECT_NEAR(o.x, 0.55f, 1e-6f);
  // Alpha is clamped: a bright camera over a dim model cannot explode.
  o = differential_compose(vec3(1.0f), vec3(0.01f), vec3(0.5f), 0.0f, eps, amax);
  EXPECT_NEAR(o.x, 1.0f + amax * 0.49f, 1e-5f);
  // Never negative.
  o = differential_compose(vec3(0.1f), vec3(0.05f), vec3(0.0f), 0.0f, eps, amax);
  EXPECT_GE(o.x, 0.0f);
  // Virtual pixels show L_rv.
  o = differential_compose(vec3(0.9f), vec3(0.1f), vec3(0.3f, 0.2f, 0.1f), 1.0f, eps, amax);
  EXPECT_NEAR(o.y, 0.2f, 1e-6f);
  // Alpha is continuous across the guard band [eps, 2 eps].
  const float a1 = compose_alpha1(0.5f, eps * 0.999f, eps, amax);
  const float a2 = compose_alpha1(0.5f, eps * 1.001f, eps, amax);
  EXPECT_NEAR(a1, a2, 1e-2f);
  EXPECT_FLOAT_EQ(compose_alpha1(0.5f, 0.0f, eps, amax), 1.0f);
}

TEST(SharedMath, DivNonnegIsTheIntegerQuotient) {
  // Every pair the shaders can meet (pixels and cells up to 8192, steps and sizes up to 1024),
  // sampled densely near multiples of b, where a rounding error would show.
  for (int b = 1; b < 1024; b += (b < 64 ? 1 : 37)) {
    for (int a = 0; a < (1 << 20); a += (a < 16384 ? 1 : 4093)) {
      ASSERT_EQ(div_nonneg1(a, b), a / b) << a << " / " << b;
      const int near = (a / b) * b;  // a multiple of b and its neighbours
      for (int d : {-1, 0, 1}) {
        const int x = near + d;
        if (x < 0) continue;
        ASSERT_EQ(div_nonneg1(x, b), x / b) << x << " / " << b;
      }
    }
  }
  // Large divisors (a quarter of a dispatch's workgroups: spread_workgroup_index).
  for (int b = 1024; b < (1 << 20); b = b * 3 + 1) {
    for (int k = 0; k * b < (1 << 20); ++k) {
      for (int d : {-1, 0, 1}) {
        const int x = k * b + d;
        if (x < 0 || x >= (1 << 20)) continue;
        ASSERT_EQ(div_nonneg1(x, b), x / b) << x << " / " << b;
      }
    }
  }
  const ivec2 q = div_nonneg(ivec2(639, 480), 4);
  EXPECT_EQ(q.x, 159);
  EXPECT_EQ(q.y, 120);
}

TEST(SharedMath, SpreadWorkgroupIndexIsABijectionThatSpreadsEachQuarter) {
  std::vector<int> seen;
  for (int n = 1; n < 700; ++n) {
    seen.assign(size_t(n), 0);
    for (int k = 0; k < n; ++k) {
      const int t = spread_workgroup_index(k, n);
      ASSERT_GE(t, 0) << k << " of " << n;
      ASSERT_LT(t, n) << k << " of " << n;
      ++seen[size_t(t)];
    }
    for (int t = 0; t < n; ++t) ASSERT_EQ(seen[size_t(t)], 1) << "tile " << t << " of " << n;
  }
  // What lavapipe's two workers get: the first half of the index range takes the tiles 0 and
  // 1 mod 4, the second 2 and 3, so each works on every row of a 20 x 15 grid (300 workgroups).
  const int gx = 20, gy = 15, n = gx * gy;
  std::vector<int> rows_first(gy, 0), rows_second(gy, 0);
  for (int k = 0; k < n; ++k) {
    const int t = spread_workgroup_index(k, n);
    (k < n / 2 ? rows_first : rows_second)[size_t(t / gx)]++;
  }
  for (int y = 0; y < gy; ++y) {
    EXPECT_EQ(rows_first[size_t(y)], gx / 2) << "row " << y;
    EXPECT_EQ(rows_second[size_t(y)], gx / 2) << "row " << y;
  }
  // Large grids (1280 x 960 and 2560 x 1920 at 8 x 8, and odd counts) stay bijective.
  for (int big : {19200, 19203, 76801}) {
    seen.assign(size_t(big), 0);
    for (int k = 0; k < big; ++k) ++seen[size_t(spread_workgroup_index(k, big))];
    for (int t = 0; t < big; ++t) ASSERT_EQ(seen[size_t(t)], 1) << "tile " << t << " of " << big;
  }
}

TEST(SharedMath, ComposeEncodedIsTheCameraModelAroundDifferentialCompose) {
  const float eps = 1e-3f, amax = 10.0f, exposure = 0.5f;
  // Equal solutions: the camera's own value back, encoded.
  const vec3 cam(0.2f, 0.4f, 0.8f);
  vec3 o = compose_encoded(cam, vec3(0.3f), vec3(0.3f), 0.0f, exposure, eps, amax);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(o[c], srgb_encode1(cam[c]), 1e-6f);
  // The solutions are seen through the exposure and clipped at 1 before the ratio.
  o = compose_encoded(cam, vec3(0.8f), vec3(0.4f), 0.0f, exposure, eps, amax);
  const vec3 want = differential_compose(cam, vec3(0.4f), vec3(0.2f), 0.0f, eps, amax);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(o[c], srgb_encode1(want[c]), 1e-6f);
  o = compose_encoded(cam, vec3(0.3f), vec3(10.0f), 1.0f, exposure, eps, amax);
  EXPECT_NEAR(o.x, 1.0f, 1e-6f) << "virtual pixel: L_rv clipped at sensor saturation";
  // Non-finite solutions, sanitised as the callers do, never reach the frame.
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const vec3 bad : {vec3(nan), vec3(inf), vec3(-inf, nan, inf)}) {
    for (const float virt : {0.0f, 1.0f}) {
      const vec3 a = compose_encoded(cam, finite3(bad), vec3(0.3f), virt, exposure, eps, amax);
      const vec3 b = compose_encoded(cam, vec3(0.3f), finite3(bad), virt, exposure, eps, amax);
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(a[c]) && a[c] >= 0.0f && a[c] <= 1.0f);
        EXPECT_TRUE(std::isfinite(b[c]) && b[c] >= 0.0f && b[c] <= 1.0f);
      }
    }
  }
}

// The tile classifier's bound (compose_tile_invisible): wherever it says a real pixel is
// invisible, the composite is within the tolerance of the camera's 8-bit value for every camera
// value, on a sweep over camera values, solutions (dark, mid, saturated) and changes; and a
// plain shadow or bounce of a few per cent is never called invisible.
TEST(SharedMath, ComposeTileInvisibleBoundsTheCompositesMove) {
  const float eps = 1e-3f, amax = 10.0f, tol = 0.5f;
  uint32_t state = 12345u;
  auto uniform = [&state]() {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24);
  };
  int invisible = 0;
  float worst = 0.0f;
  for (int k = 0; k < 200000; ++k) {
    // Solutions over decades (1e-5 .. 1) so the eps region and the clip at 1 both occur.
    const float r = std::pow(10.0f, -5.0f * uniform()) * (uniform() < 0.05f ? 2.0f : 1.0f);
    const float rel = std::pow(10.0f, -6.0f * uniform()) * (uniform() < 0.5f ? -1.0f : 1.0f);
    const float rv = std::max(0.0f, r * (1.0f + rel));
    const float cam = uniform();
    const bool inv = compose_tile_invisible(vec3(std::min(r, 1.0f)), vec3(std::min(rv, 1.0f)), eps, amax, tol);
    if (!inv) continue;
    ++invisible;
    const vec3 o = compose_encoded(vec3(cam), vec3(r), vec3(rv), 0.0f, 1.0f, eps, amax);
    worst = std::max(worst, std::abs(o.x - srgb_encode1(cam)) * 255.0f);
  }
  EXPECT_GT(invisible, 50000) << "the sweep should exercise the invisible side";
  EXPECT_LE(worst, tol * 1.01f) << "largest 8-bit move where the bound says invisible";
  for (const float r : {0.01f, 0.2f, 0.9f}) {
    EXPECT_FALSE(compose_tile_invisible(vec3(r), vec3(r * 0.97f), eps, amax, tol)) << "3% shadow at " << r;
    EXPECT_FALSE(compose_tile_invisible(vec3(r), vec3(r * 1.02f, r, r), eps, amax, tol)) << "2% red bounce at " << r;
  }
  EXPECT_TRUE(compose_tile_invisible(vec3(0.3f), vec3(0.3f), eps, amax, tol));
  EXPECT_TRUE(compose_tile_invisible(vec3(0.0f), vec3(0.0f), eps, amax, tol));
  EXPECT_FALSE(compose_tile_invisible(vec3(0.0f), vec3(1e-4f), eps, amax, tol)) << "light on an unlit surface";
}

}  // namespace
