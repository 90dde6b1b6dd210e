// How shade_direct (shading/direct_light.cpp) splits the image between its general variant and
// its real-only one (shaders/shading/direct_light.comp kRealOnly): the pixels where a virtual
// object can be, and the rest. Pure: the unit tests check that the dispatches cover the image
// exactly once.
#pragma once
#include <algorithm>
#include <array>
#include <optional>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

namespace mrgi::shading {

// One dispatch of shade_direct: its pixels [x0, x1) x [y0, y1) and whether none can be virtual.
struct ShadeDispatch {
  glm::ivec4 rect;
  bool real_only = false;
};

// The general variant over the objects' bounds (widened to whole 8 x 8 workgroups, so the bands
// start on a workgroup's edge), the real-only one over the up to four bands around them: above
// and below across the image, left and right beside the bounds. The whole image general when
// the bounds are not known; all of it real-only when there is no object. A fixed array, not a
// vector: this runs in every frame's recording, which allocates nothing.
struct ShadeDispatches {
  std::array<ShadeDispatch, 5> items{};
  size_t count = 0;
  const ShadeDispatch* begin() const { return items.data(); }
  const ShadeDispatch* end() const { return items.data() + count; }
  size_t size() const { return count; }
  const ShadeDispatch& operator[](size_t i) const { return items[i]; }
  void push_back(const ShadeDispatch& d) { items[count++] = d; }
};

inline ShadeDispatches shade_dispatches(VkExtent2D e, const std::optional<VkRect2D>& area) {
  const int w = int(e.width), h = int(e.height);
  ShadeDispatches out;
  if (!area || area->extent.width == 0 || area->extent.height == 0) {
    out.push_back({glm::ivec4(0, 0, w, h), area.has_value()});  // unknown: general; no object: real-only
    return out;
  }
  const int x0 = std::clamp(area->offset.x / 8 * 8, 0, w), y0 = std::clamp(area->offset.y / 8 * 8, 0, h);
  const int x1 = std::clamp((area->offset.x + int(area->extent.width) + 7) / 8 * 8, x0, w);
  const int y1 = std::clamp((area->offset.y + int(area->extent.height) + 7) / 8 * 8, y0, h);
  out.push_back({glm::ivec4(x0, y0, x1, y1), false});
  const glm::ivec4 bands[4] = {{0, 0, w, y0}, {0, y1, w, h}, {0, y0, x0, y1}, {x1, y0, w, y1}};
  for (const glm::ivec4& b : bands)
    if (b.z > b.x && b.w > b.y) out.push_back({b, true});
  return out;
}

}  // namespace mrgi::shading
