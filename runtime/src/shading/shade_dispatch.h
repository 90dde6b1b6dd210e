// How shade_direct (shading/direct_light.cpp) splits the image between its general variant and
// its real-only one (shaders/shading/direct_light.comp kRealOnly): the pixels where a virtual
// object can be, and the rest. Pure: the unit tests check that the dispatches cover the image
// exactly once.
#pragma once
#include <algorithm>
#include <optional>
#include <vector>

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
// the bounds are not known; all of it real-only when there is no object.
inline std::vector<ShadeDispatch> shade_dispatches(VkExtent2D e, const std::optional<VkRect2D>& area) {
  const int w = int(e.width), h = int(e.height);
  if (!area) return {{glm::ivec4(0, 0, w, h), false}};
  if (area->extent.width == 0 || area->extent.height == 0) return {{glm::ivec4(0, 0, w, h), true}};
  const int x0 = std::clamp(area->offset.x / 8 * 8, 0, w), y0 = std::clamp(area->offset.y / 8 * 8, 0, h);
  const int x1 = std::clamp((area->offset.x + int(area->extent.width) + 7) / 8 * 8, x0, w);
  const int y1 = std::clamp((area->offset.y + int(area->extent.height) + 7) / 8 * 8, y0, h);
  std::vector<ShadeDispatch> out{{glm::ivec4(x0, y0, x1, y1), false}};
  const glm::ivec4 bands[4] = {{0, 0, w, y0}, {0, y1, w, h}, {0, y0, x0, y1}, {x1, y0, w, y1}};
  for (const glm::ivec4& b : bands)
    if (b.z > b.x && b.w > b.y) out.push_back({b, true});
  return out;
}

}  // namespace mrgi::shading
