// CPU checks of the baseline's shadow-map plan (which maps, which layers, light matrices) and of
// the camera projection built from OpenCV intrinsics.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/camera_math.h"
#include "shading/shadow_plan.h"

namespace mrgi::technique {
namespace {

glm::vec3 ndc(const glm::mat4& m, const glm::vec3& p) {
  const glm::vec4 c = m * glm::vec4(p, 1.0f);
  return glm::vec3(c) / c.w;
}

LightDesc lamp(LightType type, bool real, glm::vec3 pos, glm::vec3 dir = {0, -1, 0}) {
  LightDesc l;
  l.type = type;
  l.real = real;
  l.position = pos;
  l.direction = dir;
  return l;
}

TEST(ShadowPlan, RealLampsGetTwoMapsVirtualLampsOne) {
  SceneDesc scene;
  scene.lights = {lamp(LightType::Spot, true, {0, 2, 0}), lamp(LightType::Point, false, {1, 1, 1}),
                  lamp(LightType::Point, true, {-1, 1, 0})};
  auto plan = shading::plan_shadow_maps(scene, shading::Bounds{});
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  EXPECT_EQ(plan->real_lamps, 2);
  EXPECT_EQ(plan->virtual_lamps, 1);
  ASSERT_EQ(plan->primary.size(), 1u + 6u + 6u);
  ASSERT_EQ(plan->virtual_only.size(), 1u + 6u);
  const auto& L = plan->light_set.lights;
  EXPECT_EQ(L[0].layers, glm::ivec4(0, 0, 1, 0));
  EXPECT_EQ(L[1].layers, glm::ivec4(1, -1, 6, 0));  // virtual lamp: one map, every caster
  EXPECT_EQ(L[2].layers, glm::ivec4(7, 1, 6, 0));
  for (const shading::ShadowFace& f : plan->primary) {
    EXPECT_TRUE(f.real_casters);
    EXPECT_EQ(f.virtual_casters, f.light == 1);
  }
  for (const shading::ShadowFace& f : plan->virtual_only) {
    EXPECT_FALSE(f.real_casters);
    EXPECT_TRUE(f.virtual_casters);
  }
}

TEST(ShadowPlan, CubeFacesSeeWhatTheShaderLooksUpInThem) {
  SceneDesc scene;
  scene.lights = {lamp(LightType::Point, true, {0.5f, 1.0f, -0.25f})};
  auto plan = shading::plan_shadow_maps(scene, shading::Bounds{});
  ASSERT_TRUE(plan.ok());
  const glm::vec3 pos = scene.lights[0].position;
  const glm::vec3 dirs[] = {{1, 0.3f, -0.6f}, {-1, 0.9f, 0.2f}, {0.1f, 1, 0.5f}, {0.4f, -1, -0.9f},
                            {-0.7f, 0.2f, 1}, {0.3f, -0.5f, -1}};
  for (const glm::vec3& d : dirs) {
    const int face = shading::cube_face_of(d);
    const glm::vec3 n = ndc(plan->light_set.face_view_proj[face], pos + 2.0f * d);
    EXPECT_LE(std::abs(n.x), 1.0f) << face;
    EXPECT_LE(std::abs(n.y), 1.0f) << face;
    EXPECT_GT(n.z, 0.0f);
    EXPECT_LT(n.z, 1.0f);
  }
}

// A real spot straight down from 2 m (40-degree cone) and a virtual directional lamp, over a
// 0.6 x 0.5 x 0.6 m box of bounds.
Expected<shading::ShadowPlan> spot_and_directional(shading::Bounds& b) {
  SceneDesc scene;
  LightDesc spot = lamp(LightType::Spot, true, {0, 2, 0}, {0, -1, 0});
  spot.outer_angle_deg = 40.0f;
  scene.lights = {spot, lamp(LightType::Directional, false, {0, 0, 0}, glm::normalize(glm::vec3(1, -2, 0)))};
  b.add({-0.3f, 0.0f, -0.3f}, {0.3f, 0.5f, 0.3f});
  return shading::plan_shadow_maps(scene, b);
}

TEST(ShadowPlan, SpotAndDirectionalMapsCoverTheirTargets) {
  shading::Bounds b;
  auto plan = spot_and_directional(b);
  ASSERT_TRUE(plan.ok());
  // A floor point on the spot's 35-degree line is inside its map; one at 85 degrees is not.
  const glm::vec3 inside = ndc(plan->light_set.face_view_proj[0], {2.0f * std::tan(glm::radians(35.0f)), 0, 0});
  EXPECT_LT(std::abs(inside.x), 1.0f);
  const glm::vec3 outside = ndc(plan->light_set.face_view_proj[0], {2.0f * std::tan(glm::radians(85.0f)), 0, 0});
  EXPECT_GT(std::max(std::abs(outside.x), std::abs(outside.y)), 1.0f);
  // Every bounds corner lands inside the directional lamp's ortho map.
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
    const glm::vec3 n = ndc(plan->light_set.face_view_proj[6], c);
    EXPECT_LT(std::abs(n.x), 1.0f);
    EXPECT_LT(std::abs(n.y), 1.0f);
    EXPECT_GT(n.z, 0.0f);
    EXPECT_LT(n.z, 1.0f);
  }
}

// The level of detail a face draws the virtual meshes at (shading::ShadowFace::lod_per_texel): an error
// of e metres at distance d projects to e x focal / d texels, as the face's projection maps it
// (checked against the matrix: 1 cm across the view at the target, in NDC x side / 2 texels).
TEST(ShadowPlan, FacesKnowTheirTexelScaleForTheMeshesLevelOfDetail) {
  shading::Bounds b;
  auto plan = spot_and_directional(b);
  ASSERT_TRUE(plan.ok());
  const float side = 256.0f;
  for (const shading::ShadowFace& f : plan->primary) {
    SCOPED_TRACE(f.light);
    ASSERT_GT(f.lod_per_texel.focal_px, 0.0f);
    const glm::mat4& m = plan->light_set.face_view_proj[f.light * 6 + f.face];
    const glm::vec3 target = f.light == 0 ? glm::vec3(0, 0, 0) : glm::vec3(0, 0.25f, 0);
    const glm::vec3 across = f.light == 0 ? glm::vec3(0.01f, 0, 0) : glm::vec3(0, 0, 0.01f);
    const float texels = glm::length(glm::vec2(ndc(m, target + across) - ndc(m, target))) * 0.5f * side;
    const float predicted = 0.01f * f.lod_per_texel.focal_px * side / glm::length(target - f.lod_per_texel.camera_world);
    EXPECT_NEAR(predicted / texels, 1.0f, 0.02f);
  }
}

TEST(ShadowPlan, RefusesTooManyLampsAndZeroDirections) {
  SceneDesc scene;
  scene.path = "scene.json";
  for (int i = 0; i < MRGI_MAX_LIGHTS + 1; ++i) scene.lights.push_back(lamp(LightType::Point, true, {0, 1, 0}));
  auto too_many = shading::plan_shadow_maps(scene, shading::Bounds{});
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.error().kind, ErrorKind::BadInput);
  EXPECT_NE(too_many.error().message.find("scene.json"), std::string::npos);
  scene.lights = {lamp(LightType::Spot, true, {0, 1, 0}, {0, 0, 0})};
  auto zero = shading::plan_shadow_maps(scene, shading::Bounds{});
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.error().message.find("lights[0].direction"), std::string::npos);
}

TEST(CameraProjection, OpenCvIntrinsicsMapPixelCentresAndDepth) {
  Intrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = 500;
  k.fy = 510;
  k.cx = 320.5;
  k.cy = 240.25;
  const glm::mat4 p = runtime_detail::opencv_projection(k, 0.1f, 10.0f);
  const glm::vec3 cam(0.3f, -0.2f, 2.0f);
  const glm::vec3 n = ndc(p, cam);
  // Vulkan framebuffer x = (ndc + 1) / 2 * W is the pixel's left edge + 0.5 for an OpenCV u.
  const double u = k.fx * cam.x / cam.z + k.cx, v = k.fy * cam.y / cam.z + k.cy;
  EXPECT_NEAR((n.x + 1.0) * 0.5 * k.width, u + 0.5, 1e-3);
  EXPECT_NEAR((n.y + 1.0) * 0.5 * k.height, v + 0.5, 1e-3);
  EXPECT_NEAR(ndc(p, {0, 0, 0.1f}).z, 0.0, 1e-5);
  EXPECT_NEAR(ndc(p, {0, 0, 10.0f}).z, 1.0, 1e-5);
  EXPECT_LT(ndc(p, {0, 0, 1.0f}).z, ndc(p, {0, 0, 2.0f}).z);
}

}  // namespace
}  // namespace mrgi::technique
