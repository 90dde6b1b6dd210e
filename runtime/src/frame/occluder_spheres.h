// Sphere proxies of a triangle mesh's solid, fitted once at load, for what needs a virtual
// object's occlusion of the environment cheaply (shading/environment_occlusion.h): a few spheres
// per object, tested analytically per pixel, instead of the object's triangles.
//
// The fit: the mesh is voxelised on a grid over its bounds (`grid_cells` along the longest side),
// its surface voxels marked by sampling every triangle finer than a voxel, and every other voxel
// whose centre the mesh winds around (generalised winding number >= 1/2, over a simplified copy
// of at most 1500 triangles) is solid: a scanned mesh open at its base (the Stanford bunny) is
// still a solid, where a flood fill from outside would leak in. Each solid voxel's distance to
// the nearest outside voxel is its inscribed radius. Spheres are then chosen greedily: each is the candidate (among the
// uncovered solid voxels with the largest radii) that covers the most solid voxels not covered
// yet, until `coverage` of the solid is covered or `max_spheres` are placed. So the list is in
// order of importance: its first k are the best k-sphere approximation this greedy finds, and
// a cheaper level takes a prefix.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mrgi::frame {

struct OccluderFitSettings {
  int grid_cells = 24;       // voxels along the mesh's longest side, 4..64
  int max_spheres = 16;      // 1..64
  double coverage = 0.95;    // stop once this fraction of the solid voxels is inside a sphere
  int candidates = 48;       // the largest-radius uncovered voxels scored per step
  // The reference path: every voxel's winding number summed over every triangle, where the fit
  // sums distant groups of triangles by their first-order term (and exactly near the 1/2
  // threshold). Both classify the voxels alike; for tests.
  bool exact_winding = false;
};

// Spheres (xyz centre, w radius; the mesh's own space and units), most important first. Empty
// for a mesh without triangles or with zero extent. Indices out of range are skipped.
std::vector<glm::vec4> fit_occluder_spheres(const std::vector<glm::vec3>& positions,
                                            const std::vector<uint32_t>& indices,
                                            const OccluderFitSettings& settings = {});

// Fraction of the mesh's solid voxels (on the fit's grid) inside at least one of `spheres`: how
// well a list (or a prefix of it) fills the object. For tests and the load-time report.
double occluder_coverage(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                         const std::vector<glm::vec4>& spheres, const OccluderFitSettings& settings = {});

}  // namespace mrgi::frame
