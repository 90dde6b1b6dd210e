// SH rotation in the shared header (mrgi_shared.h sh_rotate16, lpv_math.h sh4_rotate): the
// rotated coefficients evaluate, at every direction, to the original function at the direction
// turned back; band energies are kept; a rotation and its inverse return the coefficients.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "shared/lpv_math.h"

namespace {
using namespace mrgi::shader;

glm::mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  const glm::vec3 axis = glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
  std::uniform_real_distribution<float> a(0.0f, 2.0f * MRGI_PI);
  return glm::mat3(glm::rotate(glm::mat4(1.0f), a(rng), axis));
}

glm::vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  return glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
}

SH16 random_sh(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  SH16 c;
  c.c0 = vec4(u(rng), u(rng), u(rng), u(rng));
  c.c1 = vec4(u(rng), u(rng), u(rng), u(rng));
  c.c2 = vec4(u(rng), u(rng), u(rng), u(rng));
  c.c3 = vec4(u(rng), u(rng), u(rng), u(rng));
  return c;
}

float band_energy(SH16 c, int l) {
  float e = 0.0f;
  for (int i = l * l; i < (l + 1) * (l + 1); ++i) e += sh_get(c, i) * sh_get(c, i);
  return e;
}

TEST(ShRotation, Rotate16EvaluatesAsTheFunctionTurnedBack) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const SH16 c = random_sh(rng);
    const glm::mat3 r = random_rotation(rng);
    const SH16 rc = sh_rotate16(c, r);
    for (int k = 0; k < 20; ++k) {
      const glm::vec3 d = random_direction(rng);
      EXPECT_NEAR(sh_dot(rc, sh_basis16(d)), sh_dot(c, sh_basis16(glm::transpose(r) * d)), 2e-5f)
          << "trial " << trial;
    }
    for (int l = 0; l < 4; ++l) EXPECT_NEAR(band_energy(rc, l), band_energy(c, l), 1e-4f) << "band " << l;
    const SH16 back = sh_rotate16(rc, glm::transpose(r));
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(sh_get(back, i), sh_get(c, i), 2e-5f);
  }
}

TEST(ShRotation, IdentityAndAKnownQuarterTurn) {
  std::mt19937 rng(3);
  const SH16 c = random_sh(rng);
  const SH16 same = sh_rotate16(c, glm::mat3(1.0f));
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(sh_get(same, i), sh_get(c, i), 1e-5f);
  // A lobe along +x turned a quarter about z points along +y.
  const glm::mat3 quarter = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.5f * MRGI_PI, glm::vec3(0, 0, 1)));
  const SH16 lobe = sh_basis16(glm::vec3(1, 0, 0));
  const SH16 turned = sh_rotate16(lobe, quarter);
  const SH16 want = sh_basis16(glm::vec3(0, 1, 0));
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(sh_get(turned, i), sh_get(want, i), 1e-5f) << i;
}

TEST(ShRotation, Rotate4IsTheFirstTwoBandsOfRotate16) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    SH16 c = random_sh(rng);
    c.c1 = c.c2 = c.c3 = vec4(0.0f);
    const glm::mat3 r = random_rotation(rng);
    const vec4 r4 = sh4_rotate(c.c0, r);
    const SH16 r16 = sh_rotate16(c, r);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(r4[i], sh_get(r16, i), 2e-5f);
    const glm::vec3 d = random_direction(rng);
    EXPECT_NEAR(sh4_eval(r4, d), sh4_eval(c.c0, glm::transpose(r) * d), 1e-5f);
  }
}

}  // namespace
