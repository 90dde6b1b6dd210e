// Does anything virtual change what this camera sees? (docs/DESIGN.md "Scheduler and skipping": no
// virtual object in view or in its influence region -> no GI.) For the direct-light techniques
// the influence of a virtual object is the object itself and the shadow it casts from each lamp:
// the convex hull of its box and of the box pushed away from every lamp to infinity. The test is
// conservative: it only says "not in view" when one frustum plane has that whole hull outside.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/frame.h"
#include "mrgi/scene.h"

namespace mrgi::runtime {

struct InfluenceQuery {
  glm::dvec3 box_min{0.0}, box_max{0.0};  // world AABB of every virtual object together
  double margin_m = 0.05;                 // box grown by this (PCF, upsampling, depth noise)
  glm::dmat4 camera_to_world{1.0};
  Intrinsics camera;                      // image size and pinhole (OpenCV convention)
};

// True when a virtual object or its shadow from one of `lights` may be seen in the image.
// A virtual lamp lights the real scene anywhere, so any virtual lamp makes it true.
bool virtual_influence_in_view(const InfluenceQuery& q, const std::vector<LightDesc>& lights);

}  // namespace mrgi::runtime
