#include "environment_sampler.h"

#include <algorithm>
#include <cmath>

#include "sampling.h"

namespace mrgi::reference {

glm::vec2 EnvironmentSampler::direction_to_uv(const glm::vec3& d) {
  const float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * kPi);
  const float v = std::acos(glm::clamp(d.y, -1.0f, 1.0f)) / kPi;
  return {u, v};
}

glm::vec3 EnvironmentSampler::uv_to_direction(glm::vec2 uv) {
  const float phi = (uv.x - 0.5f) * 2.0f * kPi;
  const float theta = uv.y * kPi;
  const float s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

EnvironmentSampler::EnvironmentSampler(const RefEnvironment& env) {
  if (env.image.empty()) return;
  width_ = env.image.width;
  height_ = env.image.height;
  env_to_world_ = env.rotation;
  world_to_env_ = glm::transpose(env.rotation);
  radiance_.resize(size_t(width_) * height_);
  for (size_t i = 0; i < radiance_.size(); ++i) {
    const float* p = &env.image.data[i * 3];
    radiance_[i] = glm::max(glm::vec3(p[0], p[1], p[2]) * env.intensity, glm::vec3(0.0f));
    if (!finite3(radiance_[i])) radiance_[i] = glm::vec3(0.0f);
  }
  row_cdf_.assign(size_t(height_) + 1, 0.0f);
  col_cdf_.assign(size_t(height_) * (width_ + 1), 0.0f);
  row_weight_.assign(size_t(height_), 0.0f);
  double total = 0.0;
  for (int y = 0; y < height_; ++y) {
    const double sin_t = std::sin((y + 0.5) / height_ * double(kPi));
    double row = 0.0;
    float* cdf = &col_cdf_[size_t(y) * (width_ + 1)];
    for (int x = 0; x < width_; ++x) {
      row += luminance(radiance_[size_t(y) * width_ + x]) * sin_t;
      cdf[x + 1] = float(row);
    }
    for (int x = 1; x <= width_; ++x) cdf[x] = row > 0.0 ? float(cdf[x] / row) : float(x) / width_;
    row_weight_[y] = float(row);
    total += row;
    row_cdf_[y + 1] = float(total);
  }
  total_ = float(total);
  for (int y = 1; y <= height_; ++y) row_cdf_[y] = total > 0.0 ? float(row_cdf_[y] / total) : 0.0f;
}

int EnvironmentSampler::pixel_index(const glm::vec3& d_world, int* x, int* y) const {
  const glm::vec2 uv = direction_to_uv(world_to_env_ * d_world);
  *x = std::clamp(int(uv.x * width_), 0, width_ - 1);
  *y = std::clamp(int(uv.y * height_), 0, height_ - 1);
  return *y * width_ + *x;
}

glm::vec3 EnvironmentSampler::radiance(const glm::vec3& d) const {
  if (!present()) return glm::vec3(0.0f);
  int x, y;
  return radiance_[pixel_index(d, &x, &y)];
}

float EnvironmentSampler::pdf(const glm::vec3& d) const {
  if (!present() || total_ <= 0.0f) return 0.0f;
  const glm::vec3 de = world_to_env_ * d;
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - de.y * de.y));
  if (sin_t <= 1e-6f) return 0.0f;
  int x, y;
  const int i = pixel_index(d, &x, &y);
  const float row_sin = std::sin((y + 0.5f) / height_ * kPi);
  const float p = luminance(radiance_[i]) * row_sin / total_;
  return p * float(width_) * float(height_) / (2.0f * kPi * kPi * sin_t);
}

bool EnvironmentSampler::sample(glm::vec2 u, glm::vec3* d, glm::vec3* radiance, float* pdf_out) const {
  if (!present() || total_ <= 0.0f) return false;
  // Row: first y with row_cdf_[y + 1] > u.y (skips zero-weight rows).
  const auto row_it = std::upper_bound(row_cdf_.begin() + 1, row_cdf_.end(), u.y);
  const int y = std::clamp(int(row_it - row_cdf_.begin()) - 1, 0, height_ - 1);
  const float r0 = row_cdf_[y], r1 = row_cdf_[y + 1];
  const float dv = r1 > r0 ? glm::clamp((u.y - r0) / (r1 - r0), 0.0f, 0.99999994f) : 0.5f;
  const float* cdf = &col_cdf_[size_t(y) * (width_ + 1)];
  const auto col_it = std::upper_bound(cdf + 1, cdf + width_ + 1, u.x);
  const int x = std::clamp(int(col_it - cdf) - 1, 0, width_ - 1);
  const float c0 = cdf[x], c1 = cdf[x + 1];
  const float du = c1 > c0 ? glm::clamp((u.x - c0) / (c1 - c0), 0.0f, 0.99999994f) : 0.5f;
  const glm::vec2 uv((x + du) / width_, (y + dv) / height_);
  const glm::vec3 de = uv_to_direction(uv);
  const float sin_t = std::sin(uv.y * kPi);
  if (sin_t <= 1e-6f) return false;
  const glm::vec3& l = radiance_[size_t(y) * width_ + x];
  const float p = luminance(l) * std::sin((y + 0.5f) / height_ * kPi) / total_;
  if (p <= 0.0f) return false;
  *d = glm::normalize(env_to_world_ * de);
  *radiance = l;
  *pdf_out = p * float(width_) * float(height_) / (2.0f * kPi * kPi * sin_t);
  return true;
}

}  // namespace mrgi::reference
