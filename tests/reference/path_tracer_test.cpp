// Checks of the reference path tracer against cases with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "mrgi/reference/path_tracer.h"
#include "mrgi/reference/shapes.h"
#include "common/look_at.h"

namespace mrgi::reference {
namespace {

constexpr float kPi = 3.14159265358979f;


RefCamera small_camera(int w, int h, double fov_scale, glm::dmat4 pose) {
  RefCamera cam;
  cam.pinhole.width = w;
  cam.pinhole.height = h;
  cam.pinhole.fx = cam.pinhole.fy = fov_scale * w;
  cam.pinhole.cx = 0.5 * (w - 1);
  cam.pinhole.cy = 0.5 * (h - 1);
  cam.camera_to_world = pose;
  return cam;
}

RefEnvironment uniform_environment(float radiance) {
  RefEnvironment env;
  env.image = ImageRGBF(16, 8, radiance);
  return env;
}

RenderOutput render(const RefScene& scene, const RefCamera& cam, int spp, uint64_t seed = 1, int depth = 16) {
  auto tracer = PathTracer::create(scene);
  EXPECT_TRUE(tracer.ok()) << (tracer.ok() ? "" : tracer.error().message);
  RenderSettings s;
  s.spp = spp;
  s.seed = seed;
  s.max_depth = depth;
  s.rr_depth = 64;
  s.threads = 2;
  auto out = (*tracer)->render(cam, s);
  EXPECT_TRUE(out.ok());
  return std::move(out).value();
}

double mean_channel(const ImageRGBF& img, int c, const ImageU8* only_mask = nullptr) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < img.pixel_count(); ++i) {
    if (only_mask && only_mask->data[i] == 0) continue;
    sum += img.data[3 * i + c];
    ++n;
  }
  return n ? sum / double(n) : 0.0;
}

// A white object (albedo 1) in a uniform environment of radiance 1 reflects radiance 1
// everywhere: the white furnace. Run for a diffuse, a mirror and a glass sphere (glass and
// mirror conserve energy too), and a rough white metal which may only lose energy.
TEST(PathTracer, WhiteFurnace) {
  const RefCamera cam = small_camera(24, 24, 1.2, mrgi::test::opencv_look_at({0, 0, -3}, {0, 0, 0}, {0, 1, 0}));
  for (MaterialType type : {MaterialType::Diffuse, MaterialType::Mirror, MaterialType::Glass, MaterialType::Glossy}) {
    RefScene scene;
    RefMaterial m;
    m.type = type;
    m.base_color = glm::vec3(1.0f);
    m.metallic = 1.0f;
    m.roughness = 0.4f;
    scene.materials.push_back(m);
    RefMesh sphere = make_sphere(1.0f, 48, glm::mat4(1.0f));
    sphere.is_virtual = true;  // the virtual object: L_r sees the environment alone
    scene.meshes.push_back(sphere);
    scene.environment = uniform_environment(1.0f);
    const RenderOutput out = render(scene, cam, 64);
    const double rv = mean_channel(out.combined, 1, &out.virtual_mask);
    const double r = mean_channel(out.real, 1);
    EXPECT_NEAR(r, 1.0, 1e-5) << "type " << int(type);
    if (type == MaterialType::Glossy) {
      EXPECT_LT(rv, 1.01);
      EXPECT_GT(rv, 0.85);
    } else {
      EXPECT_NEAR(rv, 1.0, 0.01) << "type " << int(type);
    }
    EXPECT_EQ(out.dropped_samples, 0u);
  }
}

// Diffuse plane lit by a point lamp: L = albedo / pi * I * cos(theta) / r^2, exact with NEE.
TEST(PathTracer, PointLampOnDiffusePlaneIsAnalytic) {
  RefScene scene;
  RefMaterial m;
  m.base_color = glm::vec3(0.5f, 0.25f, 0.75f);
  scene.materials.push_back(m);
  scene.meshes.push_back(make_plane({20.0f, 20.0f}, glm::mat4(1.0f)));
  RefLight lamp;
  lamp.position = {0.3f, 1.5f, -0.2f};
  lamp.intensity = glm::vec3(10.0f);
  scene.lights.push_back(lamp);
  const RefCamera cam = small_camera(32, 32, 3.0, mrgi::test::opencv_look_at({0, 2.0, 0.001}, {0, 0, 0}, {0, 0, -1}));
  const RenderOutput out = render(scene, cam, 1, 1, 4);
  for (auto [px, py] : {std::pair{16, 16}, {3, 5}, {28, 20}, {10, 30}}) {
    // The pixel-centre ray hits depth_z along the axis; rebuild the hit point from the camera.
    const size_t i = size_t(py) * 32 + px;
    const glm::dmat4 pose = cam.camera_to_world;
    const glm::dvec3 dc((px - cam.pinhole.cx) / cam.pinhole.fx, (py - cam.pinhole.cy) / cam.pinhole.fy, 1.0);
    const glm::dvec3 p = glm::dvec3(pose * glm::dvec4(dc * double(out.depth_z[i]), 1.0));
    EXPECT_NEAR(p.y, 0.0, 1e-4);
    const glm::dvec3 to = glm::dvec3(lamp.position) - p;
    const double r2 = glm::dot(to, to);
    const double cos_t = to.y / std::sqrt(r2);
    for (int c = 0; c < 3; ++c) {
      const double expected = m.base_color[c] / kPi * 10.0 * cos_t / r2;
      // One jittered sample per pixel: the pixel footprint varies the answer by well under 1%.
      EXPECT_NEAR(out.real.data[3 * i + c], expected, 0.01 * expected) << px << "," << py << " c" << c;
    }
  }
}

// A grey floor (albedo 0.6) under a point lamp of intensity 5 at `lamp_at`, with `object`, a
// virtual mesh of material `m` (a delta material: the light tracer's caustics), over it.
RefScene floor_under_lamp_with(const RefMaterial& m, RefMesh object, const glm::vec3& lamp_at) {
  RefScene scene;
  RefMaterial floor_m;
  floor_m.base_color = glm::vec3(0.6f);
  scene.materials.push_back(floor_m);
  scene.materials.push_back(m);
  scene.meshes.push_back(make_plane({20.0f, 20.0f}, glm::mat4(1.0f)));
  object.material = 1;
  object.is_virtual = true;
  scene.meshes.push_back(std::move(object));
  RefLight lamp;
  lamp.position = lamp_at;
  lamp.intensity = glm::vec3(5.0f);
  scene.lights.push_back(lamp);
  return scene;
}

// `scene` rendered with 4 million light-traced paths beside the pixel estimator.
Expected<RenderOutput> render_light_traced(const RefScene& scene, const RefCamera& cam, int spp, int max_depth) {
  auto tracer = PathTracer::create(scene);
  if (!tracer) return tracer.error();
  RenderSettings s;
  s.spp = spp;
  s.max_depth = max_depth;
  s.rr_depth = 64;
  s.threads = 2;
  s.light_paths = 4000000;
  return (*tracer)->render(cam, s);
}

// The caustic of a point lamp in a mirror, which the pixel estimator cannot sample (a delta lamp
// seen through a delta BSDF) and the light tracer adds: a mirror ceiling at y = 2 over a lamp at
// y = 1 lights the floor like a second lamp at y = 3 (its mirror image), the floor below the lamp
// getting albedo / pi x I (1 / 1^2 + R / 3^2). Pixels away from the centre follow the same two
// lamps. The mirror is virtual: L_r is the direct light alone.
TEST(PathTracer, LightTracingAddsTheCausticOfAPointLampInAMirror) {
  RefMaterial mirror;
  mirror.type = MaterialType::Mirror;
  mirror.base_color = glm::vec3(0.9f, 0.5f, 0.25f);
  // The plane faces +y; turned over (facing down) and raised to y = 2.
  const RefScene scene = floor_under_lamp_with(
      mirror,
      make_plane({1.5f, 1.5f}, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 2.0f, 0.0f)) *
                                   glm::rotate(glm::mat4(1.0f), kPi, glm::vec3(1.0f, 0.0f, 0.0f))),
      {0.0f, 1.0f, 0.0f});
  // The camera between the lamp and the mirror, looking down (cameras are not geometry).
  const RefCamera cam = small_camera(24, 24, 2.0, mrgi::test::opencv_look_at({0, 1.5, 0.001}, {0, 0, 0}, {0, 0, -1}));
  // max_depth 1: the floor's own bounce off the mirror stays out of the analytic answer.
  auto out = render_light_traced(scene, cam, 4, 1);
  ASSERT_TRUE(out.ok()) << out.error().message;
  for (auto [px, py] : {std::pair{12, 12}, {6, 8}, {18, 15}}) {
    const size_t i = size_t(py) * 24 + size_t(px);
    const glm::dvec3 dc((px - cam.pinhole.cx) / cam.pinhole.fx, (py - cam.pinhole.cy) / cam.pinhole.fy, 1.0);
    const glm::dvec3 p = glm::dvec3(cam.camera_to_world * glm::dvec4(dc * double(out->depth_z[i]), 1.0));
    auto lamp_light = [&](glm::dvec3 at) {
      const glm::dvec3 to = at - p;
      const double r2 = glm::dot(to, to);
      return to.y / std::sqrt(r2) / r2;
    };
    for (int c = 0; c < 3; ++c) {
      const double direct = 0.6 / kPi * 5.0 * lamp_light({0.0, 1.0, 0.0});
      const double caustic = 0.6 / kPi * 5.0 * mirror.base_color[c] * lamp_light({0.0, 3.0, 0.0});
      EXPECT_NEAR(out->real.data[3 * i + c], direct, 0.01 * direct) << px << "," << py;
      EXPECT_NEAR(out->combined.data[3 * i + c], direct + caustic, 0.05 * caustic + 0.01 * direct) << px << "," << py << " c" << c;
    }
  }
}

// A clear glass sphere above a floor under a point lamp: the light it bends still reaches the
// floor (the pixel estimator alone leaves its shadow black but for the sky): over the floor the
// camera sees, the power with the sphere is the power without it less what the sphere reflects
// away and what lands outside the view (a few percent: the focus is under the sphere).
TEST(PathTracer, LightTracingKeepsTheLightAGlassSphereBends) {
  RefMaterial glass;
  glass.type = MaterialType::Glass;
  glass.base_color = glm::vec3(1.0f);
  glass.ior = 1.5f;
  const RefScene scene = floor_under_lamp_with(
      glass, make_sphere(0.25f, 64, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.6f, 0.0f))), {0.0f, 2.0f, 0.0f});
  const RefCamera cam = small_camera(48, 48, 0.6, mrgi::test::opencv_look_at({0, 3.0, 0.001}, {0, 0, 0}, {0, 0, -1}));
  auto out = render_light_traced(scene, cam, 8, 8);
  ASSERT_TRUE(out.ok()) << out.error().message;
  double with = 0.0, without = 0.0;
  for (size_t i = 0; i < out->real.pixel_count(); ++i) {
    if (out->virtual_mask.data[i] != 0) continue;  // the floor, where the sphere does not hide it
    with += out->combined.data[3 * i + 1];
    without += out->real.data[3 * i + 1];
  }
  EXPECT_GT(with, 0.85 * without) << "the light through the glass is lost";
  EXPECT_LT(with, 1.0 * without);
}

// Spot lamp: full intensity inside the inner cone, none outside the outer cone.
TEST(PathTracer, SpotConeLimitsLight) {
  RefScene scene;
  scene.materials.push_back(RefMaterial{});
  scene.meshes.push_back(make_plane({20.0f, 20.0f}, glm::mat4(1.0f)));
  RefLight spot;
  spot.type = RefLightType::Spot;
  spot.position = {0.0f, 1.0f, 0.0f};
  spot.direction = {0.0f, -1.0f, 0.0f};
  spot.intensity = glm::vec3(5.0f);
  spot.cos_inner = std::cos(20.0f * kPi / 180.0f);
  spot.cos_outer = std::cos(30.0f * kPi / 180.0f);
  scene.lights.push_back(spot);
  const RefCamera cam = small_camera(41, 41, 0.5, mrgi::test::opencv_look_at({0, 3.0, 0.001}, {0, 0, 0}, {0, 0, -1}));
  const RenderOutput out = render(scene, cam, 1, 1, 0);
  const float centre = out.real.data[(20 * 41 + 20) * 3];
  EXPECT_NEAR(centre, 0.8f / kPi * 5.0f, 0.01f);
  // tan(30 deg) * 1 m = 0.577 m from the centre is the edge of the cone; the corner is far out.
  EXPECT_EQ(out.real.data[0], 0.0f);
}

// Monte Carlo error falls as 1/sqrt(spp): 16x the samples, about a quarter of the error.
TEST(PathTracer, ErrorFallsWithSquareRootOfSamples) {
  RefScene scene;
  scene.materials.push_back(RefMaterial{});
  scene.meshes.push_back(make_plane({20.0f, 20.0f}, glm::mat4(1.0f)));
  RefMaterial box_mat;
  box_mat.base_color = glm::vec3(0.9f, 0.2f, 0.2f);
  scene.materials.push_back(box_mat);
  RefMesh box = make_box({0.5f, 0.5f, 0.5f}, glm::translate(glm::mat4(1.0f), {0.0f, 0.25f, 0.0f}));
  box.material = 1;
  scene.meshes.push_back(box);
  scene.environment = uniform_environment(1.0f);
  const RefCamera cam = small_camera(16, 16, 0.7, mrgi::test::opencv_look_at({1.5, 1.5, -1.5}, {0, 0, 0}, {0, 1, 0}));
  const RenderOutput truth = render(scene, cam, 1024, 99, 4);
  auto rms_error = [&](int spp) {
    double sum = 0.0;
    int runs = 0;
    for (uint64_t seed = 1; seed <= 4; ++seed, ++runs) {
      const RenderOutput o = render(scene, cam, spp, seed, 4);
      for (size_t i = 0; i < o.real.data.size(); ++i) {
        const double d = o.real.data[i] - truth.real.data[i];
        sum += d * d;
      }
    }
    return std::sqrt(sum / runs);
  };
  const double e4 = rms_error(4), e64 = rms_error(64);
  EXPECT_GT(e4 / e64, 2.8);
  EXPECT_LT(e4 / e64, 5.5);
}

// The same seed gives bit-identical images whatever the thread count; another seed does not.
TEST(PathTracer, DeterministicPerSeed) {
  RefScene scene;
  scene.materials.push_back(RefMaterial{});
  scene.meshes.push_back(make_plane({4.0f, 4.0f}, glm::mat4(1.0f)));
  RefMesh ball = make_sphere(0.3f, 16, glm::translate(glm::mat4(1.0f), {0.0f, 0.3f, 0.0f}));
  ball.is_virtual = true;
  scene.meshes.push_back(ball);
  scene.environment = uniform_environment(0.5f);
  RefLight lamp;
  lamp.position = {0.5f, 1.0f, 0.5f};
  scene.lights.push_back(lamp);
  const RefCamera cam = small_camera(20, 15, 0.8, mrgi::test::opencv_look_at({0, 1.0, -1.5}, {0, 0, 0}, {0, 1, 0}));
  auto tracer = PathTracer::create(scene);
  ASSERT_TRUE(tracer.ok());
  RenderSettings s;
  s.spp = 4;
  s.threads = 1;
  const RenderOutput a = (*tracer)->render(cam, s).value();
  s.threads = 3;
  const RenderOutput b = (*tracer)->render(cam, s).value();
  s.seed = 2;
  const RenderOutput c = (*tracer)->render(cam, s).value();
  EXPECT_EQ(a.real.data, b.real.data);
  EXPECT_EQ(a.combined.data, b.combined.data);
  EXPECT_NE(a.real.data, c.real.data);
}

// The virtual ball shadows the floor: L_rv < L_r under it, and where nothing virtual matters
// (a pixel far from the ball, seen past it) the two are bit-identical.
TEST(PathTracer, DifferenceIsExactlyZeroWhereNothingVirtualMatters) {
  RefScene scene;
  scene.materials.push_back(RefMaterial{});
  scene.meshes.push_back(make_plane({4.0f, 4.0f}, glm::mat4(1.0f)));
  RefMesh ball = make_sphere(0.2f, 16, glm::translate(glm::mat4(1.0f), {0.0f, 0.5f, 0.0f}));
  ball.is_virtual = true;
  scene.meshes.push_back(ball);
  RefLight lamp;
  lamp.position = {1.0f, 2.0f, 0.0f};
  lamp.intensity = glm::vec3(4.0f);
  scene.lights.push_back(lamp);
  const RefCamera cam = small_camera(32, 32, 0.5, mrgi::test::opencv_look_at({0, 3.0, 0.001}, {0, 0, 0}, {0, 0, -1}));
  const RenderOutput out = render(scene, cam, 8, 1, 2);
  // Centre: the ball itself. One pixel off the ball, in its shadow (the lamp is above it).
  EXPECT_EQ(out.virtual_mask.data[16 * 32 + 16], 255);
  const size_t corner = 0;
  EXPECT_EQ(out.virtual_mask.data[corner], 0);
  EXPECT_EQ(out.real.data[corner * 3], out.combined.data[corner * 3]);
  // The lamp is off to +x, so the ball's shadow falls beside it, in view.
  int shadowed = 0;
  for (size_t i = 0; i < out.virtual_mask.pixel_count(); ++i)
    if (!out.virtual_mask.data[i] && out.combined.data[3 * i] < 0.5f * out.real.data[3 * i]) ++shadowed;
  EXPECT_GT(shadowed, 0);
}

// Non-uniform environment over a white diffuse plane: the radiance is (1/pi) * integral of
// L(w) cos(theta) over the upper hemisphere, computed here by brute force over the environment
// pixels. Checks the importance sampling pdf, the MIS weights and the equirectangular mapping.
TEST(PathTracer, EnvironmentLightingMatchesNumericIntegral) {
  RefScene scene;
  RefMaterial white;
  white.base_color = glm::vec3(1.0f);
  scene.materials.push_back(white);
  scene.meshes.push_back(make_plane({2000.0f, 2000.0f}, glm::mat4(1.0f)));
  RefEnvironment env;
  env.image = ImageRGBF(32, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      // A bright patch ("sun") plus a smooth sky and a coloured gradient.
      const bool sun = x == 21 && y == 4;
      env.image.at(x, y)[0] = sun ? 200.0f : 0.2f + 0.05f * float(x % 7);
      env.image.at(x, y)[1] = sun ? 180.0f : 0.3f + 0.02f * float(y);
      env.image.at(x, y)[2] = sun ? 150.0f : 0.5f;
    }
  env.rotation = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(0.0f, 1.0f, 0.0f)));
  scene.environment = env;
  // Brute force: sub-sample each pixel 16x16 (the map is piecewise constant per pixel).
  glm::dvec3 expected(0.0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      for (int sy = 0; sy < 16; ++sy)
        for (int sx = 0; sx < 16; ++sx) {
          const double u = (x + (sx + 0.5) / 16.0) / 32.0, v = (y + (sy + 0.5) / 16.0) / 16.0;
          const double theta = v * kPi, phi = (u - 0.5) * 2.0 * kPi;
          const glm::vec3 de(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
          const glm::vec3 dw = env.rotation * de;
          if (dw.y <= 0.0f) continue;
          const double dw_solid = std::sin(theta) * (kPi / 16.0 / 16.0) * (2.0 * kPi / 32.0 / 16.0);
          for (int c = 0; c < 3; ++c) expected[c] += env.image.at(x, y)[c] * dw.y * dw_solid / kPi;
        }
  const RefCamera cam = small_camera(8, 8, 2.0, mrgi::test::opencv_look_at({0, 1.0, 0.001}, {0, 0, 0}, {0, 0, -1}));
  const RenderOutput out = render(scene, cam, 512, 3, 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean_channel(out.real, c), expected[c], 0.02 * expected[c]) << "c" << c;
}

TEST(PathTracer, RefusesBrokenScenes) {
  RefScene scene;
  scene.materials.push_back(RefMaterial{});
  RefMesh mesh = make_plane({1.0f, 1.0f}, glm::mat4(1.0f));
  mesh.indices.push_back(99);
  mesh.indices.push_back(0);
  mesh.indices.push_back(1);
  scene.meshes.push_back(mesh);
  auto t = PathTracer::create(scene);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().message.find("vertex index out of range"), std::string::npos);
  scene.meshes[0] = make_plane({1.0f, 1.0f}, glm::mat4(1.0f));
  scene.meshes[0].positions[0].x = std::nanf("");
  EXPECT_FALSE(PathTracer::create(scene).ok());
  scene.meshes[0] = make_plane({1.0f, 1.0f}, glm::mat4(1.0f));
  RefLight bad;
  bad.intensity = glm::vec3(-1.0f);
  scene.lights.push_back(bad);
  EXPECT_FALSE(PathTracer::create(scene).ok());
}

}  // namespace
}  // namespace mrgi::reference
