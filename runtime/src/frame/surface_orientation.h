// A virtual object's surface by orientation, gathered once at load: what its surface sends a
// viewer in direction v when lit by a light from direction l depends on how much of its area
// faces both (a box lit from above shows a viewer beside it only dark sides; a sphere shows
// part of its lit half). The triangles' area-weighted normals are clustered into at most
// `max_patches` oriented patches (spherical k-means, seeded farthest-first over the normals'
// 128-direction histogram), each keeping the area-weighted mean normal and albedo of its
// triangles: a box's six faces come out exact, a rounded object as a few representative
// orientations. shading/environment_occlusion.h lights them as convex patches (no shadowing
// between them) for the light an object sends on to the surfaces around it.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mrgi::frame {

struct OrientedPatch {
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  // unit, the mesh's space
  float area = 0.0f;                   // the mesh's units squared
  glm::vec3 albedo{0.0f};              // area-weighted mean diffuse albedo, linear RGB
  // |sum of the triangles' area x unit normal|: the area the patch shows a distant viewer
  // along its normal (= area for a flat patch, less for a curved one). Half the sum over the
  // patches of facing_area x |dot(normal, w)| is the object's silhouette area seen from
  // direction w, exact for a convex mesh whose patches are flat.
  float facing_area = 0.0f;
};

// Patches of the triangles (positions indexed by `indices`, three a triangle; out-of-range
// indices and degenerate triangles skipped), `triangle_albedo` one per triangle (indices.size()
// / 3 of them). Largest area first; empty for a mesh without area. max_patches 1..64.
std::vector<OrientedPatch> cluster_surface_orientations(const std::vector<glm::vec3>& positions,
                                                        const std::vector<uint32_t>& indices,
                                                        const std::vector<glm::vec3>& triangle_albedo,
                                                        int max_patches);

}  // namespace mrgi::frame
