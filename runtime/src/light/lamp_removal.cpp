#include "light/lamp_removal.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "light/sh_tools.h"

namespace mrgi::light {
namespace {

double pixel_luminance(const float* p) { return luminance(glm::dvec3(p[0], p[1], p[2])); }

}  // namespace

bool project_to_env_image(const EnvCamera& camera, int width, int height, const glm::dvec3& world_direction,
                          glm::dvec2& pixel) {
  const glm::dvec3 d = glm::normalize(glm::inverse(glm::mat3_cast(camera.rotation)) * world_direction);
  if (camera.model == EnvModel::FisheyeEquidistant) {
    const double theta = std::acos(std::clamp(d.z, -1.0, 1.0));
    if (theta > 0.5 * camera.fov_deg * kPi / 180.0) return false;
    const double rho = std::sqrt(d.x * d.x + d.y * d.y);
    const double r = camera.f * theta;
    pixel = rho > 1e-12 ? glm::dvec2(camera.cx + r * d.x / rho, camera.cy + r * d.y / rho) : glm::dvec2(camera.cx, camera.cy);
  } else {
    const double u = 0.5 + std::atan2(d.x, -d.z) / (2.0 * kPi), v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
    pixel = glm::dvec2(u * width - 0.5, v * height - 0.5);
  }
  return pixel.x > -0.5 && pixel.y > -0.5 && pixel.x < width - 0.5 && pixel.y < height - 0.5;
}

int LampRemoval::apply(ImageRGBF& image, const EnvCamera& camera, const std::vector<LightDesc>& lamps) {
  if (image.empty()) return 0;
  // Pixels per radian near the lamp: the fisheye's f, or an equirectangular image's width / 2 pi
  // (its rows; columns shrink towards the poles, which only makes the mask and ring rounder).
  const double px_per_rad = camera.model == EnvModel::FisheyeEquidistant ? camera.f : image.width / (2.0 * kPi);
  int removed = 0;
  for (const LightDesc& l : lamps) {
    if (!l.real || !(std::max({l.color.x, l.color.y, l.color.z}) * l.intensity > 0.0f)) continue;
    glm::dvec3 dir;
    if (l.type == LightType::Directional) {
      dir = -glm::dvec3(l.direction);
    } else {
      if (!camera.position) continue;
      dir = glm::dvec3(l.position) - *camera.position;
    }
    if (!(glm::length(dir) > 1e-9)) continue;
    glm::dvec2 at;
    if (!project_to_env_image(camera, image.width, image.height, glm::normalize(dir), at)) continue;
    removed += remove_one(image, camera, at, px_per_rad) ? 1 : 0;
  }
  return removed;
}

bool LampRemoval::remove_one(ImageRGBF& image, const EnvCamera&, const glm::dvec2& at, double px_per_rad) {
  const int w = image.width, h = image.height;
  const double deg = px_per_rad * kPi / 180.0;  // pixels per degree
  const double search = std::max(1.0, settings_.search_deg * deg), reach = std::max(2.0, settings_.max_deg * deg);
  const double r0 = std::max(reach + 1.0, settings_.ring_inner_deg * deg), r1 = std::max(r0 + 2.0, settings_.ring_outer_deg * deg);
  // The ring: the background's median (threshold) and mean (fill), over its pixels holding light.
  ring_.clear();
  glm::dvec3 sum(0.0);
  const int x0 = std::max(0, int(std::floor(at.x - r1))), x1 = std::min(w - 1, int(std::ceil(at.x + r1)));
  const int y0 = std::max(0, int(std::floor(at.y - r1))), y1 = std::min(h - 1, int(std::ceil(at.y + r1)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double r = glm::length(glm::dvec2(x, y) - at);
      const float* p = image.at(x, y);
      if (r < r0 || r > r1 || !(pixel_luminance(p) > 0.0)) continue;
      ring_.push_back(float(pixel_luminance(p)));
    }
  if (ring_.size() < 4) return false;
  std::nth_element(ring_.begin(), ring_.begin() + std::ptrdiff_t(ring_.size() / 2), ring_.end());
  const double threshold = settings_.contrast * double(ring_[ring_.size() / 2]);
  size_t n = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double r = glm::length(glm::dvec2(x, y) - at);
      const float* p = image.at(x, y);
      if (r < r0 || r > r1 || !(pixel_luminance(p) > 0.0) || pixel_luminance(p) >= threshold) continue;
      sum += glm::dvec3(p[0], p[1], p[2]);
      ++n;
    }
  if (n == 0) return false;
  const glm::dvec3 fill = sum / double(n);
  // The seed: the brightest pixel within `search` of the projection; nothing bright, nothing removed.
  int seed = -1;
  double best = threshold;
  for (int y = std::max(0, int(at.y - search)); y <= std::min(h - 1, int(at.y + search)); ++y)
    for (int x = std::max(0, int(at.x - search)); x <= std::min(w - 1, int(at.x + search)); ++x)
      if (glm::length(glm::dvec2(x, y) - at) <= search && pixel_luminance(image.at(x, y)) > best) {
        best = pixel_luminance(image.at(x, y));
        seed = y * w + x;
      }
  if (seed < 0) return false;
  mask_.assign(size_t(w) * size_t(h), 0);
  stack_.clear();
  stack_.push_back(seed);
  mask_[size_t(seed)] = 1;
  while (!stack_.empty()) {
    const int c = stack_.back();
    stack_.pop_back();
    const int cx = c % w, cy = c / w;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= w || y >= h || mask_[size_t(y) * w + x]) continue;
        if (glm::length(glm::dvec2(x, y) - at) > reach || pixel_luminance(image.at(x, y)) < threshold) continue;
        mask_[size_t(y) * w + x] = 1;
        stack_.push_back(y * w + x);
      }
  }
  // One pixel more all round: the bulb's anti-aliased edge and the start of its glare.
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      if (mask_[size_t(y) * w + x] != 1) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < w && yy < h && !mask_[size_t(yy) * w + xx]) mask_[size_t(yy) * w + xx] = 2;
        }
    }
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (mask_[size_t(y) * w + x]) {
        float* p = image.at(x, y);
        p[0] = float(fill.x), p[1] = float(fill.y), p[2] = float(fill.z);
      }
  return true;
}

}  // namespace mrgi::light
