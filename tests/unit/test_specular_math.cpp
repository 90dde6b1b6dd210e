// The specular stage's math (shaders/shared/specular_math.h) on the CPU: what shaders/specular/
// trace.comp runs for mirrors and glass.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bsdf.h"
#include "shared/specular_math.h"
#include "specular/caustic_receiver.glsl"

namespace {
using namespace mrgi::shader;

TEST(SpecularMath, KindsFollowTheMaterial) {
  EXPECT_EQ(specular_kind(0.0f, 0.0f, 1.0f), SPECULAR_REFRACTIVE);
  EXPECT_EQ(specular_kind(0.0f, 0.5f, 0.3f), SPECULAR_REFRACTIVE);
  EXPECT_EQ(specular_kind(1.0f, 0.0f, 0.0f), SPECULAR_REFLECTIVE);
  EXPECT_EQ(specular_kind(1.0f, 0.1f, 0.0f), SPECULAR_REFLECTIVE);
  EXPECT_EQ(specular_kind(1.0f, 0.3f, 0.0f), SPECULAR_NONE);   // brushed metal: glossy, not an image
  EXPECT_EQ(specular_kind(0.0f, 0.0f, 0.0f), SPECULAR_NONE);   // smooth plastic: 4 % reflection
  EXPECT_EQ(specular_kind(1.0f, 1.0f, 0.0f), SPECULAR_NONE);   // glTF's default material
}

TEST(SpecularMath, DielectricFresnelMatchesTheReferenceRenderer) {
  // The path tracer's smooth dielectric (tools/reference/src/bsdf.h) is the ground truth the
  // suite's glass is rendered with: the same reflectance at every angle, both ways through.
  for (float eta : {1.0f / 1.5f, 1.5f, 1.0f / 1.33f}) {
    for (float c = 0.02f; c <= 1.0f; c += 0.07f) {
      float cos_t = 0.0f;
      const float reference = mrgi::reference::bsdf_detail::fresnel_dielectric(c, eta, &cos_t);
      EXPECT_NEAR(fresnel_dielectric(c, eta), reference, 1e-5f) << "eta " << eta << " cos " << c;
    }
  }
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / 1.5f), 0.04f, 1e-4f);  // ((n - 1) / (n + 1))^2
  EXPECT_FLOAT_EQ(fresnel_dielectric(0.1f, 1.5f), 1.0f);            // total internal reflection
}

TEST(SpecularMath, SnellBendsTowardsTheNormalEnteringGlass) {
  const vec3 n(0.0f, 0.0f, 1.0f);
  const float s = std::sin(0.6f);
  const vec3 d = normalize(vec3(s, 0.0f, -std::cos(0.6f)));
  const vec4 t = refract_or_reflect(d, n, 1.0f / 1.5f);
  ASSERT_GT(t.w, 0.5f);
  EXPECT_NEAR(t.x, s / 1.5f, 1e-5f);  // sin(theta_t) = sin(theta_i) / n
  EXPECT_LT(t.z, 0.0f);               // through the surface
  EXPECT_NEAR(length(vec3(t)), 1.0f, 1e-5f);
  // Leaving the glass past the critical angle (41.8 degrees): reflected back inside.
  const vec3 steep = normalize(vec3(std::sin(0.9f), 0.0f, std::cos(0.9f)));
  const vec4 tir = refract_or_reflect(steep, -n, 1.5f);
  EXPECT_EQ(tir.w, 0.0f);
  EXPECT_NEAR(tir.z, -steep.z, 1e-5f);
  // A slab with parallel faces: the ray leaves in the direction it came.
  const vec4 out = refract_or_reflect(vec3(t), n, 1.5f);  // the far face, its normal against the ray
  ASSERT_GT(out.w, 0.5f);
  EXPECT_NEAR(out.x, d.x, 1e-5f);
  EXPECT_NEAR(out.z, d.z, 1e-5f);
}

TEST(SpecularMath, TransmittanceTintsAtBothInterfacesAndAbsorbsWithDistance) {
  const vec3 base(0.5f, 1.0f, 1.0f);
  EXPECT_NEAR(transmittance_colour(base, vec3(1.0f), 0.0f, 3.0f).x, 0.25f, 1e-6f);
  // Beer: the attenuation colour after attenuation_distance, its square after twice that.
  const vec3 a = transmittance_colour(vec3(1.0f), vec3(0.5f, 0.8f, 1.0f), 0.1f, 0.2f);
  EXPECT_NEAR(a.x, 0.25f, 1e-5f);
  EXPECT_NEAR(a.y, 0.64f, 1e-5f);
  EXPECT_NEAR(a.z, 1.0f, 1e-6f);
}

TEST(SpecularMath, ComposeKeepsTheCameraWhereNothingVirtualChangesThePath) {
  const float eps = 1e-3f, alpha_max = 10.0f;
  // A real hit lit the same with and without the objects: the camera's colour as it is.
  const vec3 camera(0.3f, 0.2f, 0.1f);
  const vec3 l(0.25f, 0.25f, 0.25f);
  vec3 out = specular_compose(l, l, camera, vec3(0.0f), eps, alpha_max);
  EXPECT_NEAR(out.x, 0.3f, 1e-6f);
  EXPECT_NEAR(out.z, 0.1f, 1e-6f);
  // Half the light with the objects (a virtual shadow on the hit): half the camera's colour.
  out = specular_compose(0.5f * l, l, camera, vec3(0.0f), eps, alpha_max);
  EXPECT_NEAR(out.x, 0.15f, 1e-6f);
  // Every back-projection failed (camera = L'_r): the rendered L'_rv, plus the environment.
  out = specular_compose(vec3(0.4f), l, l, vec3(0.1f), eps, alpha_max);
  EXPECT_NEAR(out.y, 0.5f, 1e-6f);
  // A virtual hit only (L'_r = 0, no camera term): its rendered light.
  out = specular_compose(vec3(0.2f, 0.3f, 0.4f), vec3(0.0f), vec3(0.0f), vec3(0.0f), eps, alpha_max);
  EXPECT_NEAR(out.z, 0.4f, 1e-6f);
}

TEST(SpecularMath, CubeFacesCoverEveryDirectionOnce) {
  // The face a direction falls on, and its coordinates, agree with the face's own axes: the
  // centre of face f looks along its forward axis; the image's x grows along right, y along down.
  for (int f = 0; f < 6; ++f) {
    const vec3 fwd = specular_face_forward(f), r = specular_face_right(f), dn = specular_face_down(f);
    EXPECT_NEAR(dot(glm::cross(r, dn), fwd), 1.0f, 1e-6f) << "face " << f << " is right-handed";
    const vec3 c = specular_cube_face(fwd);
    EXPECT_EQ(int(c.z), f);
    EXPECT_NEAR(c.x, 0.5f, 1e-6f);
    EXPECT_NEAR(c.y, 0.5f, 1e-6f);
    const vec3 right_edge = specular_cube_face(normalize(fwd + 0.99f * r));
    EXPECT_EQ(int(right_edge.z), f);
    EXPECT_NEAR(right_edge.x, 0.995f, 1e-4f);
    const vec3 bottom = specular_cube_face(normalize(fwd + 0.5f * dn));
    EXPECT_NEAR(bottom.y, 0.75f, 1e-5f);
  }
}


TEST(SpecularMath, CubeFaceClosedFormMatchesTheFaceAxes) {
  // specular_cube_face's selects give what projecting onto the chosen face's own axes gives
  // (the impostor faces are drawn with those axes, specular.cpp).
  for (int i = 0; i < 4000; ++i) {
    const float a = 0.731f * float(i), b = 0.377f * float(i) + 0.2f;
    const vec3 d = normalize(vec3(std::cos(a) * std::sin(b), std::cos(b), std::sin(a) * std::sin(b)));
    const vec3 c = specular_cube_face(d);
    const int f = int(c.z);
    const float z = dot(d, specular_face_forward(f));
    ASSERT_GT(z, 0.0f) << i;
    const float ad = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    EXPECT_FLOAT_EQ(z, ad) << "the major axis, direction " << i;
    EXPECT_NEAR(c.x, std::clamp(dot(d, specular_face_right(f)) / z * 0.5f + 0.5f, 0.0f, 1.0f), 1e-6f) << i;
    EXPECT_NEAR(c.y, std::clamp(dot(d, specular_face_down(f)) / z * 0.5f + 0.5f, 0.0f, 1.0f), 1e-6f) << i;
  }
}

TEST(SpecularMath, OctahedralTexelsCoverTheSphereOnce) {
  // The receiver maps' texels (oct_texel_solid_angle at each texel's centre direction) add up
  // to the sphere's 4 pi: a photon's irradiance over its square keeps its flux anywhere in the map.
  for (const int size : {64, 256}) {
    double sum = 0.0;
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const vec2 e((float(x) + 0.5f) / float(size) * 2.0f - 1.0f, (float(y) + 0.5f) / float(size) * 2.0f - 1.0f);
        sum += oct_texel_solid_angle(oct_decode(e), float(size));
      }
    }
    EXPECT_NEAR(sum, 4.0 * M_PI, 4.0 * M_PI * (size == 64 ? 2e-3 : 2e-4)) << size;
  }
  EXPECT_FLOAT_EQ(oct_texel_solid_angle(vec3(0.0f, 0.0f, 1.0f), 2.0f), 1.0f);  // a pole
  EXPECT_NEAR(oct_texel_solid_angle(normalize(vec3(1.0f)), 2.0f), 3.0f * std::sqrt(3.0f), 1e-4f);
  // The solid angle of a small patch of texels matches its directions' spherical area.
  const int size = 512;
  const vec2 e0(0.3f, -0.45f);
  const float h = 4.0f / float(size);  // 2 x 2 texels
  const vec3 a = oct_decode(e0), b = oct_decode(e0 + vec2(h, 0.0f)), c = oct_decode(e0 + vec2(0.0f, h));
  const float patch = length(glm::cross(b - a, c - a));  // small: the chord parallelogram's area
  EXPECT_NEAR(4.0f * oct_texel_solid_angle(oct_decode(e0 + vec2(0.5f * h)), float(size)), patch, patch * 0.02f);
}

TEST(SpecularMath, AReceiverMapsHalvingsTileItsAtlasBlockWithoutOverlap) {
  // Each lamp's block is 1.5 size x size texels: mip 0, then the halvings in a column beside it;
  // no two levels share a texel and every one lies inside the block.
  for (const int size : {16, 64, 512}) {
    const glm::ivec2 origin(3 * size / 2, 0);  // the second lamp's block
    std::vector<int> owner(size_t(3 * size / 2) * size_t(size), -1);
    for (int k = 0; k < MRGI_CAUSTIC_RECEIVER_LEVELS && (size >> k) >= 4; ++k) {
      const glm::ivec2 o = caustic_receiver_origin(origin, size, k) - origin;
      const int side = size >> k;
      ASSERT_GE(o.x, 0);
      ASSERT_GE(o.y, 0);
      ASSERT_LE(o.x + side, 3 * size / 2) << "size " << size << " level " << k;
      ASSERT_LE(o.y + side, size) << "size " << size << " level " << k;
      for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
          int& w = owner[size_t(o.y + y) * size_t(3 * size / 2) + size_t(o.x + x)];
          EXPECT_EQ(w, -1) << "size " << size << " level " << k << " overlaps level " << w;
          w = k;
        }
    }
  }
}

TEST(SpecularMath, AReceiverSquareKeepsThePhotonsFlux) {
  // The square covers the photon's footprint on the surface (spacing^2) at any distance and
  // tilt, to within the side's rounding to whole texels; its area is always that of the side
  // drawn (side^2 texels' patches), so each texel's flux / area adds up to the photon's flux.
  const float texel_sr = oct_texel_solid_angle(normalize(vec3(0.2f, -0.1f, 1.0f)), 512.0f);
  for (float r : {0.5f, 1.0f, 3.0f}) {
    for (float cos_l : {1.0f, 0.5f, 0.2f}) {
      const vec2 q = caustic_receiver_square(0.05f, r, cos_l, texel_sr, 1.0f, 1000.0f);
      EXPECT_EQ(q.x, std::floor(q.x)) << "whole texels";
      const float exact = 0.05f * std::sqrt(cos_l) / (r * std::sqrt(texel_sr));  // unrounded side
      EXPECT_NEAR(q.x, exact, 0.5f);
      EXPECT_NEAR(q.y, 0.05f * 0.05f * (q.x * q.x) / (exact * exact), 1e-6f) << r << " " << cos_l;
    }
  }
  const vec2 small = caustic_receiver_square(1e-5f, 1.0f, 1.0f, texel_sr, 1.0f, 16.0f);
  EXPECT_FLOAT_EQ(small.x, 1.0f);
  EXPECT_NEAR(small.y, texel_sr, texel_sr * 1e-5f);  // one texel's patch at 1 m, facing the lamp
  const vec2 grazing = caustic_receiver_square(0.01f, 1.0f, 0.0f, texel_sr, 1.0f, 1e6f);
  EXPECT_TRUE(std::isfinite(grazing.y) && grazing.y > 0.0f);
  // The same-surface rule both caustic paths use: 3 % + 1 cm of the surface's distance.
  EXPECT_TRUE(caustic_same_surface(1.0f, 1.039f));
  EXPECT_FALSE(caustic_same_surface(1.0f, 1.041f));
  EXPECT_FALSE(caustic_same_surface(1.0f, 0.959f));
}

}  // namespace
