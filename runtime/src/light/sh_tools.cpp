#include "light/sh_tools.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "shared/mrgi_shared.h"

namespace mrgi::light {
namespace {

// Clamped-cosine zonal factors A_l (Ramamoorthi & Hanrahan 2001) for l = 0..3.
constexpr double kCosineLobe[kMaxShBands] = {kPi, 2.0 * kPi / 3.0, kPi / 4.0, 0.0};

}  // namespace

ShVector sh_basis(const glm::vec3& direction) {
  ShVector out{};
  const float len = glm::length(direction);
  if (!(len > 0.0f) || !std::isfinite(len)) return out;
  const shader::SH16 b = shader::sh_basis16(direction / len);
  for (int i = 0; i < kMaxShCoeffs; ++i) out[i] = shader::sh_get(b, i);
  return out;
}

int sh_band(int coefficient) {
  int l = 0;
  while ((l + 1) * (l + 1) <= coefficient) ++l;
  return l;
}

ShRgb sh_directional_light(const glm::dvec3& direction_to_light, const glm::dvec3& irradiance,
                           int bands) {
  ShRgb out{};
  const ShVector y = sh_basis(glm::vec3(direction_to_light));
  for (int i = 0; i < bands * bands && i < kMaxShCoeffs; ++i) out[i] = irradiance * double(y[i]);
  return out;
}

glm::dvec3 sh_evaluate(const ShRgb& l, const glm::vec3& direction) {
  const ShVector y = sh_basis(direction);
  glm::dvec3 sum(0.0);
  for (int i = 0; i < kMaxShCoeffs; ++i) sum += l[i] * double(y[i]);
  return sum;
}

glm::dvec3 sh_irradiance(const ShRgb& l, const glm::vec3& normal) {
  const ShVector y = sh_basis(normal);
  glm::dvec3 sum(0.0);
  for (int i = 0; i < kMaxShCoeffs; ++i) sum += kCosineLobe[sh_band(i)] * l[i] * double(y[i]);
  return sum;
}

bool sh_dominant_direction(const ShRgb& l, glm::dvec3& out) {
  // Band 1 in Sloan order is (Y1-1, Y10, Y11) = c * (-y, z, -x): the vector of coefficients maps
  // back to a direction as (-L11, -L1-1, L10).
  const glm::dvec3 d(-luminance(l[3]), -luminance(l[1]), luminance(l[2]));
  const double len = glm::length(d);
  if (!(len > 1e-30) || !std::isfinite(len)) return false;
  out = d / len;
  return true;
}

glm::dvec3 sh_dominant_intensity(const ShRgb& l, const glm::dvec3& direction) {
  const ShVector y = sh_basis(glm::vec3(direction));
  glm::dvec3 num(0.0);
  double den = 0.0;
  for (int i = 1; i < 9; ++i) {
    const double a = kCosineLobe[sh_band(i)];
    num += a * a * l[i] * double(y[i]);
    den += a * a * double(y[i]) * double(y[i]);
  }
  if (!(den > 0.0)) return glm::dvec3(0.0);
  return glm::max(num / den, glm::dvec3(0.0));
}

void fill_light_estimate(const ShRgb& l, int bands, LightEstimate& out) {
  out.bands = bands;
  for (int i = 0; i < kMaxShCoeffs; ++i) {
    const glm::dvec3 c = i < bands * bands ? l[i] : glm::dvec3(0.0);
    out.sh_radiance[i] = {float(c.x), float(c.y), float(c.z)};
    if (i < 9) {
      const glm::dvec3 e = c * kCosineLobe[sh_band(i)];
      out.irradiance_sh9[i] = {float(e.x), float(e.y), float(e.z)};
    }
  }
  glm::dvec3 dir(out.direction_to_light[0], out.direction_to_light[1], out.direction_to_light[2]);
  if (sh_dominant_direction(l, dir)) {
    out.direction_to_light = {float(dir.x), float(dir.y), float(dir.z)};
  }
  const glm::dvec3 c = sh_dominant_intensity(l, dir);
  out.dominant_intensity = {float(c.x), float(c.y), float(c.z)};
}

bool is_finite(const ShRgb& l) {
  for (const auto& c : l)
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) return false;
  return true;
}

glm::dvec3 fibonacci_direction(int k, int count) {
  const double y = 1.0 - 2.0 * (k + 0.5) / count;
  const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
  const double phi = kPi * (3.0 - std::sqrt(5.0)) * k;
  return glm::dvec3(r * std::cos(phi), y, r * std::sin(phi));
}

}  // namespace mrgi::light

namespace mrgi {

Rgb irradiance_at(const LightEstimate& estimate, const std::array<float, 3>& normal) {
  const glm::vec3 n(normal[0], normal[1], normal[2]);
  const light::ShVector y = light::sh_basis(n);
  Rgb out{0.0f, 0.0f, 0.0f};
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c) out[c] += estimate.irradiance_sh9[i][c] * y[i];
  return out;
}

Expected<LightEstimate> light_from_environment(const ImageRGBF& image, const EnvCamera& camera,
                                               double intensity, int bands) {
  using light::kPi;
  if (image.empty() || image.width < 1 || image.height < 1)
    return fail(ErrorKind::BadInput, "light_from_environment: empty environment image");
  const bool fisheye = camera.model == EnvModel::FisheyeEquidistant;
  if (fisheye && !(camera.f > 0.0))
    return fail(ErrorKind::BadInput, "light_from_environment: fisheye env camera needs f > 0 (pixels)");
  if (bands < 1 || bands > light::kMaxShBands)
    return fail(ErrorKind::BadUsage, "light_from_environment: bands must be 1..4");
  const glm::dmat3 rot = glm::mat3_cast(camera.rotation);
  const double half_fov = 0.5 * camera.fov_deg * kPi / 180.0;
  light::ShRgb sh{};
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      glm::dvec3 d;
      double solid_angle = 0.0;
      if (fisheye) {
        const double dx = u - camera.cx, dy = v - camera.cy, r = std::sqrt(dx * dx + dy * dy);
        const double theta = r / camera.f;
        if (theta > half_fov) continue;
        const double s = std::sin(theta);
        d = r > 0.0 ? glm::dvec3(s * dx / r, s * dy / r, std::cos(theta)) : glm::dvec3(0, 0, 1);
        // Equidistant: r dr dphi = f^2 theta dtheta dphi and dOmega = sin(theta) dtheta dphi.
        solid_angle = theta > 1e-9 ? s / (theta * camera.f * camera.f) : 1.0 / (camera.f * camera.f);
      } else {
        const double pu = (u + 0.5) / image.width, pv = (v + 0.5) / image.height;
        const double theta = pv * kPi, phi = (pu - 0.5) * 2.0 * kPi;
        d = glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
        solid_angle = std::sin(theta) * (kPi / image.height) * (2.0 * kPi / image.width);
      }
      const float* t = image.at(u, v);
      glm::dvec3 c(t[0], t[1], t[2]);
      for (int i = 0; i < 3; ++i)
        if (!(c[i] >= 0.0) || std::isinf(c[i])) c[i] = 0.0;
      const light::ShVector y = light::sh_basis(glm::vec3(rot * d));
      for (int i = 0; i < bands * bands; ++i)
        sh[size_t(i)] += c * (intensity * solid_angle * double(y[size_t(i)]));
    }
  }
  LightEstimate out;
  light::fill_light_estimate(sh, bands, out);
  out.valid = true;
  out.confidence = 1.0f;
  out.frame_index = -1;
  return out;
}

double direction_error_deg(const LightEstimate& a, const LightEstimate& b) {
  const glm::dvec3 da(a.direction_to_light[0], a.direction_to_light[1], a.direction_to_light[2]);
  const glm::dvec3 db(b.direction_to_light[0], b.direction_to_light[1], b.direction_to_light[2]);
  const double c = glm::dot(glm::normalize(da), glm::normalize(db));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

}  // namespace mrgi
