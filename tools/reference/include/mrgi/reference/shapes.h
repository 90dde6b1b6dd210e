// Simple shapes generated in code for scene descriptions and tests, as world-space triangle
// meshes with outward (front-face, counter-clockwise) winding and smooth/flat normals.
#pragma once
#include <glm/glm.hpp>

#include "mrgi/reference/path_tracer.h"

namespace mrgi::reference {

// Square-cornered rectangle in the object's x-z plane, centred at the origin, normal +y,
// size.x along x and size.y along z (metres).
RefMesh make_plane(glm::vec2 size, const glm::mat4& object_to_world);
// Axis-aligned box centred at the origin with edge lengths `size` (metres), flat faces.
RefMesh make_box(glm::vec3 size, const glm::mat4& object_to_world);
// UV sphere centred at the origin, smooth normals; `segments` around (>= 8), half as many rings.
RefMesh make_sphere(float radius, int segments, const glm::mat4& object_to_world);

}  // namespace mrgi::reference
