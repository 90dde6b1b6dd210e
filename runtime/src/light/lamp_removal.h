// Declared lamps removed from an environment camera's image before it is sampled into light: a
// real lamp that is declared (scene.json `lights`, or tracked) lights the scene through its own
// model (point, spot, directional, with shadow maps); if the env camera also sees its bulb, the
// same light would come in a second time as an environment region (a tenth of a fisheye's
// energy for a desk lamp in view). Where each lamp projects into the image (the env camera's
// pose: its rotation, and its position for a lamp at a position), the bulb and its glare (the
// connected pixels around that point brighter than `contrast` times the median of a ring around
// it) are replaced by the ring's mean radiance: the background the lamp stands in front of.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/frame.h"
#include "mrgi/image.h"
#include "mrgi/scene.h"

namespace mrgi::light {

struct LampRemovalSettings {
  // A pixel is part of the lamp when its luminance is at least this many times the ring's median.
  double contrast = 4.0;
  // Angles from the lamp's projected direction, degrees: the seed is the brightest pixel within
  // `search_deg` (a lamp's declared position is known to a few centimetres); the mask grows at
  // most to `max_deg`; the ring that stands for the background is [ring_inner_deg, ring_outer_deg].
  double search_deg = 3.0, max_deg = 10.0, ring_inner_deg = 11.0, ring_outer_deg = 15.0;
};

// Where a world direction (unit, from the env camera) lands in its image, pixel coordinates
// (continuous, integer = pixel centre); false outside the image (or the fisheye's field of view).
bool project_to_env_image(const EnvCamera& camera, int width, int height, const glm::dvec3& world_direction,
                          glm::dvec2& pixel);

class LampRemoval {
 public:
  explicit LampRemoval(const LampRemovalSettings& settings = {}) : settings_(settings) {}
  // Removes from `image` (linear radiance) every lamp of `lamps` that is real, lit and in view:
  // point and spot lamps need camera.position, directional ones only the rotation. Returns how
  // many were removed. Working memory is kept between calls (no allocation after the first
  // image of a size).
  int apply(ImageRGBF& image, const EnvCamera& camera, const std::vector<LightDesc>& lamps);

 private:
  bool remove_one(ImageRGBF& image, const EnvCamera& camera, const glm::dvec2& at, double px_per_rad);
  LampRemovalSettings settings_;
  std::vector<uint8_t> mask_;
  std::vector<int32_t> stack_;
  std::vector<float> ring_;
};

}  // namespace mrgi::light
