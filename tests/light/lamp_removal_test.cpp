// Declared lamps taken out of an env camera's image (runtime/src/light/lamp_removal.h): the bulb
// and its glare where the lamp projects become the background around it; what is not a declared
// lamp stays; a lamp out of view, unlit or without the camera's position changes nothing.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "light/lamp_removal.h"

namespace {
using namespace mrgi;
using namespace mrgi::light;

constexpr double kPi = 3.14159265358979323846;

// An upward 180-degree equidistant fisheye of 128 px at (0, 1, 0).
EnvCamera up_fisheye(bool with_position = true) {
  EnvCamera c;
  c.model = EnvModel::FisheyeEquidistant;
  c.f = 64.0 / (kPi / 2.0);
  c.cx = c.cy = 63.5;
  c.fov_deg = 180.0;
  c.rotation = glm::angleAxis(-kPi / 2.0, glm::dvec3(1, 0, 0));  // camera +z = world +y
  if (with_position) c.position = glm::dvec3(0.0, 1.0, 0.0);
  return c;
}

// Sky of radiance 0.2 inside the image circle, with bright discs (radius 2 px, radiance 50).
ImageRGBF sky_with_discs(const std::vector<glm::dvec2>& discs) {
  ImageRGBF img(128, 128);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      float l = std::hypot(x - 63.5, y - 63.5) <= 64.0 ? 0.2f : 0.0f;
      for (const glm::dvec2& d : discs)
        if (glm::length(glm::dvec2(x, y) - d) <= 2.0) l = 50.0f;
      float* p = img.at(x, y);
      p[0] = p[1] = p[2] = l;
    }
  return img;
}

float max_near(const ImageRGBF& img, glm::dvec2 at, double r) {
  float m = 0.0f;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (glm::length(glm::dvec2(x, y) - at) <= r) m = std::max(m, img.at(x, y)[1]);
  return m;
}

LightDesc point_lamp(glm::vec3 position) {
  LightDesc l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = 3.0f;
  return l;
}

TEST(LampRemoval, ADeclaredBulbBecomesTheSkyBehindIt) {
  const EnvCamera cam = up_fisheye();
  const LightDesc lamp = point_lamp(glm::vec3(0.3f, 2.0f, 0.1f));
  glm::dvec2 at;
  ASSERT_TRUE(project_to_env_image(cam, 128, 128, glm::normalize(glm::dvec3(lamp.position) - *cam.position), at));
  const glm::dvec2 other(30.0, 90.0);  // a bright thing nobody declared (a window, the sun)
  ImageRGBF img = sky_with_discs({at, other});
  LampRemoval removal;
  EXPECT_EQ(removal.apply(img, cam, {lamp}), 1);
  EXPECT_NEAR(max_near(img, at, 4.0), 0.2f, 1e-4f);
  EXPECT_EQ(max_near(img, other, 1.0), 50.0f);
}

TEST(LampRemoval, WhatItCannotPlaceOrSeeIsLeftAlone) {
  const LightDesc lamp = point_lamp(glm::vec3(0.3f, 2.0f, 0.1f));
  glm::dvec2 at;
  const EnvCamera cam = up_fisheye();
  ASSERT_TRUE(project_to_env_image(cam, 128, 128, glm::normalize(glm::dvec3(lamp.position) - *cam.position), at));
  LampRemoval removal;
  {  // no camera position: a point lamp cannot be placed
    ImageRGBF img = sky_with_discs({at});
    EXPECT_EQ(removal.apply(img, up_fisheye(false), {lamp}), 0);
    EXPECT_EQ(max_near(img, at, 1.0), 50.0f);
  }
  {  // below the fisheye's horizon
    ImageRGBF img = sky_with_discs({at});
    EXPECT_EQ(removal.apply(img, cam, {point_lamp(glm::vec3(0.3f, 0.2f, 0.1f))}), 0);
    EXPECT_EQ(max_near(img, at, 1.0), 50.0f);
  }
  {  // a virtual lamp or one switched off is not in the camera's image
    LightDesc virt = lamp, off = lamp;
    virt.real = false;
    off.intensity = 0.0f;
    ImageRGBF img = sky_with_discs({at});
    EXPECT_EQ(removal.apply(img, cam, {virt, off}), 0);
  }
  {  // declared where nothing bright is: nothing to take out
    ImageRGBF img = sky_with_discs({});
    EXPECT_EQ(removal.apply(img, cam, {lamp}), 0);
  }
}

TEST(LampRemoval, ADeclaredSunNeedsNoPosition) {
  const EnvCamera cam = up_fisheye(false);
  LightDesc sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(-0.3f, -1.0f, 0.2f));  // where the light goes
  glm::dvec2 at;
  ASSERT_TRUE(project_to_env_image(cam, 128, 128, -glm::dvec3(sun.direction), at));
  ImageRGBF img = sky_with_discs({at});
  LampRemoval removal;
  EXPECT_EQ(removal.apply(img, cam, {sun}), 1);
  EXPECT_NEAR(max_near(img, at, 4.0), 0.2f, 1e-4f);
}

}  // namespace
