// Importance sampling of an image by hierarchical warping (Clarberg et al. 2005; the shared
// step is mrgi_shared.h warp_step, so a GPU pass that walks a mip pyramid of importance in a
// shader makes the same choices for the same u): VPLs drawn from a reflective shadow map's flux,
// lights drawn from an environment image or the light stage's samples. This is the host side:
// the pyramid of a small image (an environment's luminance, a light-stage grid) built once and
// sampled many times; dir's RSM pass walks the same levels on the GPU.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/expected.h"
#include "shared/mrgi_shared.h"

namespace mrgi::gi {

struct ImportanceSample {
  glm::ivec2 texel{0};         // in the image
  glm::vec2 position{0.0f};    // continuous, in texels (texel + offset in [0, 1)^2)
  float probability = 0.0f;    // of this texel: its importance / the image's total
};

class ImportancePyramid {
 public:
  // `importance`: width x height values, row-major, >= 0 (negative and NaN count as 0). The
  // image is padded with zeros to a square power of two; an all-zero image samples uniformly.
  static Expected<ImportancePyramid> create(int width, int height, const std::vector<float>& importance) {
    if (width < 1 || height < 1 || width > 8192 || height > 8192)
      return fail(ErrorKind::BadUsage, "ImportancePyramid: size must be 1..8192 per side");
    if (importance.size() != size_t(width) * size_t(height))
      return fail(ErrorKind::BadUsage, "ImportancePyramid: " + std::to_string(importance.size()) +
                                           " values for " + std::to_string(width) + "x" + std::to_string(height));
    ImportancePyramid p;
    p.width_ = width;
    p.height_ = height;
    int side = 1;
    while (side < std::max(width, height)) side *= 2;
    // levels_[0] is the finest (side x side), the last one 1 x 1.
    for (int s = side; s >= 1; s /= 2) p.levels_.push_back(std::vector<float>(size_t(s) * size_t(s), 0.0f));
    double total = 0.0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float v = importance[size_t(y) * size_t(width) + size_t(x)];
        const float clean = v > 0.0f && std::isfinite(v) ? v : 0.0f;
        p.levels_[0][size_t(y) * size_t(side) + size_t(x)] = clean;
        total += clean;
      }
    p.uniform_ = !(total > 0.0);
    if (p.uniform_)  // every real texel equally likely, the padding never
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) p.levels_[0][size_t(y) * size_t(side) + size_t(x)] = 1.0f;
    for (size_t l = 1; l < p.levels_.size(); ++l) {
      const int s = side >> l, f = s * 2;
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
          const std::vector<float>& c = p.levels_[l - 1];
          p.levels_[l][size_t(y) * size_t(s) + size_t(x)] =
              c[size_t(2 * y) * size_t(f) + size_t(2 * x)] + c[size_t(2 * y) * size_t(f) + size_t(2 * x + 1)] +
              c[size_t(2 * y + 1) * size_t(f) + size_t(2 * x)] + c[size_t(2 * y + 1) * size_t(f) + size_t(2 * x + 1)];
        }
    }
    return p;
  }

  // u in [0, 1)^2 (a stratified or low-discrepancy point set keeps its stratification).
  ImportanceSample sample(glm::vec2 u) const {
    glm::ivec2 at(0);
    float probability = 1.0f;
    glm::vec2 w = glm::clamp(u, glm::vec2(0.0f), glm::vec2(0.99999994f));
    for (size_t l = levels_.size() - 1; l > 0; --l) {
      const std::vector<float>& c = levels_[l - 1];
      const int f = 1 << (levels_.size() - l);  // side of the child level
      const glm::ivec2 b = at * 2;
      const glm::vec4 q(c[size_t(b.y) * size_t(f) + size_t(b.x)], c[size_t(b.y) * size_t(f) + size_t(b.x + 1)],
                        c[size_t(b.y + 1) * size_t(f) + size_t(b.x)], c[size_t(b.y + 1) * size_t(f) + size_t(b.x + 1)]);
      const shader::WarpStep step = shader::warp_step(w, q);
      at = b + step.child;
      w = step.u;
      probability *= step.probability;
    }
    ImportanceSample s;
    s.texel = glm::min(at, glm::ivec2(width_ - 1, height_ - 1));
    s.position = glm::vec2(s.texel) + w;
    s.probability = probability;
    return s;
  }

  // The probability sample() gives `texel` (importance / total; 0 outside the image).
  float probability(glm::ivec2 texel) const {
    if (texel.x < 0 || texel.y < 0 || texel.x >= width_ || texel.y >= height_) return 0.0f;
    const int side = int(std::lround(std::sqrt(double(levels_[0].size()))));
    return levels_[0][size_t(texel.y) * size_t(side) + size_t(texel.x)] / levels_.back()[0];
  }
  bool uniform() const { return uniform_; }

 private:
  int width_ = 0, height_ = 0;
  bool uniform_ = false;
  std::vector<std::vector<float>> levels_;
};

}  // namespace mrgi::gi
