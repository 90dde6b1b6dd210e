// The voxel cone tracing math of dvct (shaders/shared/vct_math.h) on the CPU: the functions the
// cone-tracing shaders run.
#include <gtest/gtest.h>

#include <cmath>

#include "shared/vct_math.h"

namespace {
using namespace mrgi::shader;

constexpr double kPi = 3.14159265358979323846;

TEST(VctMath, StepsMakeTouchingFootprints) {
  // Each sample's ball touches the next one's: d' - d = (D(d) + D(d')) / 2.
  for (float aperture : {0.2f, 0.6f, 1.0f, 1.4f}) {
    const float r = vct_diameter_ratio(aperture);
    float d = 4.0f;
    for (int k = 0; k < 10; ++k) {
      const float next = vct_next_distance(r, d, 0.5f);
      EXPECT_NEAR(next - d, 0.5f * (vct_diameter(r, d, 0.5f) + vct_diameter(r, next, 0.5f)), 1e-3f * next)
          << "aperture " << aperture << " step " << k;
      d = next;
    }
  }
  // Near the apex the footprint's floor rules: steps of min_diameter.
  EXPECT_FLOAT_EQ(vct_next_distance(0.1f, 0.2f, 0.5f), 0.7f);
  // A cone wider than the step rule takes is clamped to it, and steps stay finite.
  EXPECT_FLOAT_EQ(vct_diameter_ratio(3.0f), VCT_MAX_DIAMETER_RATIO);
  EXPECT_TRUE(std::isfinite(vct_next_distance(vct_diameter_ratio(3.0f), 10.0f, 0.5f)));
}

TEST(VctMath, LodIsTheFootprintsMipLevel) {
  EXPECT_FLOAT_EQ(vct_lod(1.0f, 6.0f), 0.0f);
  EXPECT_FLOAT_EQ(vct_lod(4.0f, 6.0f), 2.0f);
  EXPECT_FLOAT_EQ(vct_lod(0.25f, 6.0f), 0.0f);   // under a voxel: the finest level
  EXPECT_FLOAT_EQ(vct_lod(1024.0f, 6.0f), 6.0f);  // beyond the chain: its last level
}

TEST(VctMath, AccumulationIsFrontToBack) {
  // An opaque sample hides everything behind it.
  vec4 acc(0.0f);
  acc = vct_accumulate(acc, vec3(0.5f), 1.0f);
  acc = vct_accumulate(acc, vec3(9.0f), 1.0f);
  EXPECT_FLOAT_EQ(acc.x, 0.5f);
  EXPECT_FLOAT_EQ(acc.w, 1.0f);
  // Two half-occluding samples: the second is seen through the first.
  acc = vct_accumulate(vec4(0.0f), vec3(0.2f), 0.5f);
  acc = vct_accumulate(acc, vec3(0.2f), 0.5f);
  EXPECT_FLOAT_EQ(acc.x, 0.2f + 0.2f * 0.5f);
  EXPECT_FLOAT_EQ(acc.w, 0.75f);
  // Occlusion never leaves [0, 1].
  acc = vct_accumulate(vec4(0.0f), vec3(0.0f), 7.0f);
  EXPECT_FLOAT_EQ(acc.w, 1.0f);
}

// Why the light accumulation departs from the paper's printed formula (vct_accumulate): with it,
// light gathered from a half-occluding voxel fades at every empty sample the cone takes after it.
TEST(VctMath, ThePrintedFormulaWouldFadeLightInEmptySpace) {
  auto printed = [](vec4 acc, vec3 light, float occ) {
    const float l = acc.x * acc.w + light.x * occ * (1.0f - acc.w);
    return vec4(l, l, l, acc.w + occ * (1.0f - acc.w));
  };
  vec4 ours = vct_accumulate(vec4(0.0f), vec3(0.4f), 0.5f);
  vec4 theirs = printed(vec4(0.0f), vec3(0.4f), 0.5f);
  for (int empty = 0; empty < 6; ++empty) {
    ours = vct_accumulate(ours, vec3(0.0f), 0.0f);
    theirs = printed(theirs, vec3(0.0f), 0.0f);
  }
  EXPECT_FLOAT_EQ(ours.x, 0.4f);           // what the voxel sent, however far the cone runs
  EXPECT_LT(theirs.x, 0.4f * 0.5f * 0.1f);  // 0.2 x 0.5^6: gone
}

TEST(VctMath, OcclusionFollowsTheStoredNormal) {
  const vec3 up(0.0f, 0.0f, 1.0f), side(1.0f, 0.0f, 0.0f);
  const vec4 flat(0.0f, 0.0f, 1.0f, 1.0f);  // one flat surface filling the voxel
  // Full occlusion head-on, the floor edge-on, |cos| between.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(flat, up, 0.1f, 0.0f), 1.0f);
  EXPECT_FLOAT_EQ(vct_directional_occlusion(flat, side, 0.1f, 0.0f), 0.1f);
  const vec3 d = normalize(vec3(1.0f, 0.0f, 1.0f));
  EXPECT_NEAR(vct_directional_occlusion(flat, d, 0.1f, 0.0f), std::sqrt(0.5f), 1e-6f);
  // Either side of the surface hides the same.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, -1.0f, 1.0f), d, 0.1f, 0.0f),
                  vct_directional_occlusion(flat, d, 0.1f, 0.0f));
  // Surfaces facing every way (mean normal 0): the same from every direction.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, 0.0f, 0.6f), d, 0.1f, 0.0f), 0.6f);
  // Level 1 over a one-voxel floor spanning the cell: 4 of its 8 sub-voxels (premultiplied: n
  // 4/8, o 4/8), one coherent surface covering the footprint: opaque head-on, as at level 0.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, 0.5f, 0.5f), up, 0.1f, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, 0.5f, 0.5f), side, 0.1f, 1.0f), 0.1f);
  // Level 2 over a floor covering half the cell's columns (8 of 64 sub-voxels): half covered.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, 0.125f, 0.125f), up, 0.1f, 2.0f), 0.5f);
  // Clutter (no coherent normal) at level 1 covers its occupancy, not more.
  EXPECT_FLOAT_EQ(vct_directional_occlusion(vec4(0.0f, 0.0f, 0.0f, 0.5f), up, 0.1f, 1.0f), 0.5f);
  // Two perpendicular surfaces (a mean normal of length 0.707): between the two cases.
  const vec4 corner(0.5f, 0.0f, 0.5f, 1.0f);
  const float seen = vct_directional_occlusion(corner, side, 0.1f, 0.0f);
  EXPECT_GT(seen, 0.5f);
  EXPECT_LT(seen, 1.0f);
  // Empty: nothing, whatever the normal says.
  EXPECT_EQ(vct_directional_occlusion(vec4(0.3f, 0.0f, 0.0f, 0.0f), d, 0.1f, 0.0f), 0.0f);
}

TEST(VctMath, ASampleSeesAFrontFaceByItsProjectedCoverageAndNoBackFace) {
  const vec4 wall(0.0f, 0.0f, 1.0f, 1.0f);  // a wall facing +z filling the voxel
  const vec3 radiance(2.0f, 4.0f, 6.0f);
  // Looking at its front (the cone travels -z): all of its light, fully occluded.
  vec4 s = vct_sample(radiance, wall, vec3(0.0f, 0.0f, -1.0f), 0.1f, 0.0f);
  EXPECT_FLOAT_EQ(s.x, 2.0f);
  EXPECT_FLOAT_EQ(s.w, 1.0f);
  // At 60 degrees: half the coverage, half the light (radiance per projected area unchanged:
  // light and occlusion shrink together, so a cone stopped by it reads the radiance).
  const vec3 oblique = normalize(vec3(std::sqrt(3.0f), 0.0f, -1.0f));
  s = vct_sample(radiance, wall, oblique, 0.1f, 0.0f);
  EXPECT_NEAR(s.w, 0.5f, 1e-5f);
  EXPECT_NEAR(s.y, 2.0f, 1e-5f);
  // From behind: it occludes, it sends nothing.
  s = vct_sample(radiance, wall, vec3(0.0f, 0.0f, 1.0f), 0.1f, 0.0f);
  EXPECT_FLOAT_EQ(s.w, 1.0f);
  EXPECT_FLOAT_EQ(s.x, 0.0f);
  // Surfaces facing every way: their light whatever the direction.
  s = vct_sample(radiance, vec4(0.0f, 0.0f, 0.0f, 0.5f), vec3(0.0f, 0.0f, 1.0f), 0.1f, 0.0f);
  EXPECT_FLOAT_EQ(s.x, 2.0f);
  EXPECT_FLOAT_EQ(s.w, 0.5f);
  // Empty: nothing.
  EXPECT_EQ(vct_sample(radiance, vec4(0.0f), vec3(0.0f, 0.0f, 1.0f), 0.1f, 0.0f), vec4(0.0f));
}

TEST(VctMath, DiffuseConesIntegrateTheCosineOverTheHemisphere) {
  for (int n : {1, 5, 6, 9, 12, 16}) {
    double weights = 0.0, solid = 0.0;
    for (int i = 0; i < n; ++i) {
      const VctCone c = vct_diffuse_cone(i, n);
      EXPECT_NEAR(glm::length(c.dir), 1.0f, 1e-5f);
      EXPECT_GT(c.dir.z, 0.0f) << "cone " << i << " of " << n << " points into the surface";
      EXPECT_GT(c.weight, 0.0f);
      EXPECT_GT(c.aperture, 0.0f);
      weights += c.weight;
      solid += 2.0 * kPi * (1.0 - std::cos(0.5 * c.aperture));
    }
    // A uniform radiance L gives irradiance pi L.
    EXPECT_NEAR(weights, kPi, 1e-4) << n << " cones";
    // The cones cover the hemisphere (one cone: as much as the widest aperture the step rule
    // takes, 84 degrees, covers).
    EXPECT_GT(solid, (n == 1 ? 0.25 : 0.9) * 2.0 * kPi) << n << " cones";
  }
  // Irradiance from light straight above falls off with the angle: a cone set's response to a
  // directional source is largest on the normal's cone.
  const VctCone up = vct_diffuse_cone(0, 9), side = vct_diffuse_cone(8, 9);
  EXPECT_GT(up.weight, side.weight);
  // No two cones of a set point the same way.
  for (int i = 0; i < 9; ++i)
    for (int j = i + 1; j < 9; ++j)
      EXPECT_LT(glm::dot(vct_diffuse_cone(i, 9).dir, vct_diffuse_cone(j, 9).dir), 0.99f) << i << " " << j;
}

TEST(VctMath, SpecularApertureFollowsRoughness) {
  const float min_aperture = 0.02f;
  EXPECT_FLOAT_EQ(vct_specular_aperture(0.0f, min_aperture), min_aperture);  // a mirror
  float last = 0.0f;
  for (float r = 0.1f; r <= 1.0f; r += 0.1f) {
    const float a = vct_specular_aperture(r, min_aperture);
    EXPECT_GE(a, last) << "roughness " << r;
    last = a;
  }
  // Half power of GGX at roughness 0.5 (alpha 0.25): half vector at atan(0.6436 x 0.25) = 9.1
  // degrees, the reflection twice that: a cone of 2 x 18.3 degrees.
  EXPECT_NEAR(vct_specular_aperture(0.5f, min_aperture), 2.0 * 2.0 * std::atan(0.6436 * 0.25), 1e-5);
  // Roughness 1 is clamped to the widest cone the step rule takes.
  EXPECT_FLOAT_EQ(vct_specular_aperture(1.0f, min_aperture), 2.0f * std::atan(0.5f * VCT_MAX_DIAMETER_RATIO));
}

TEST(VctMath, ShorterStepsKeepTheTransmittanceOfTheSameDepth) {
  const float ratio = vct_diameter_ratio(1.0f);
  // step_scale 1 is the paper's step; 0.5 goes half as far.
  EXPECT_FLOAT_EQ(vct_step(ratio, 4.0f, 0.5f, 1.0f), vct_next_distance(ratio, 4.0f, 0.5f));
  EXPECT_FLOAT_EQ(vct_step(ratio, 4.0f, 0.5f, 0.5f) - 4.0f, 0.5f * (vct_next_distance(ratio, 4.0f, 0.5f) - 4.0f));
  // Two half steps through the same medium let through what one full step does.
  for (float a : {0.0f, 0.1f, 0.5f, 0.9f}) {
    const float half = vct_opacity_for_step(a, 0.5f);
    EXPECT_NEAR((1.0f - half) * (1.0f - half), 1.0f - a, 1e-5f) << a;
    EXPECT_FLOAT_EQ(vct_opacity_for_step(a, 1.0f), a);
  }
  EXPECT_FLOAT_EQ(vct_opacity_for_step(1.0f, 0.5f), 1.0f) << "opaque stays opaque";
  // The light scales with the occlusion, so their ratio (the voxel's radiance) is kept.
  const vec4 s(0.2f, 0.4f, 0.6f, 0.5f);
  const vec3 l = vct_light_for_step(s, 0.5f);
  EXPECT_NEAR(l.x / vct_opacity_for_step(0.5f, 0.5f), 0.2f / 0.5f, 1e-5f);
  EXPECT_EQ(vct_light_for_step(vec4(0.0f), 0.5f), vec3(0.0f));
}

TEST(VctMath, SpecularWeightIsTheLobesDirectionalAlbedo) {
  // A smooth dielectric seen head-on reflects about its f0; a mirror-like metal its colour;
  // grazing angles reflect more (Fresnel); rough surfaces less at grazing than smooth ones.
  EXPECT_NEAR(vct_specular_weight(vec3(0.04f), 0.0f, 1.0f).x, 0.04f, 0.01f);
  EXPECT_NEAR(vct_specular_weight(vec3(0.9f), 0.0f, 1.0f).x, 0.9f, 0.05f);
  EXPECT_GT(vct_specular_weight(vec3(0.04f), 0.0f, 0.05f).x, vct_specular_weight(vec3(0.04f), 0.0f, 1.0f).x);
  EXPECT_LT(vct_specular_weight(vec3(0.04f), 1.0f, 0.1f).x, vct_specular_weight(vec3(0.04f), 0.0f, 0.1f).x);
  for (float r = 0.0f; r <= 1.0f; r += 0.25f)
    for (float nv = 0.0f; nv <= 1.0f; nv += 0.25f) {
      const vec3 w = vct_specular_weight(vec3(0.5f), r, nv);
      EXPECT_GE(w.x, 0.0f);
      EXPECT_LE(w.x, 1.0f);
    }
}

}  // namespace
