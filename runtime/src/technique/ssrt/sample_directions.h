// The visibility sample directions of the ssrt technique (paper Sec. 5.1): N jittered directions
// on the whole sphere, one set per pixel of a 2x2 block ("random offsets for an area of 2x2
// pixels"), each with its pre-computed SH weights, a pseudo-random displacement length, and the
// continuous-visibility threshold chi of eq. 9 from the median neighbour angle of a spherical
// Delaunay triangulation of the samples.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/expected.h"

namespace mrgi::ssrt {

constexpr int kJitterSets = 4;  // 2x2 pixels

// One sample as the shaders read it (std430, 80 bytes): direction (world space, unit) and the
// displacement as a fraction of the sampling radius in (0, 1]; then the 16 SH weights
// Y_i(w) * solid angle (4 pi / N), so the transfer projection is one multiply-add per coefficient.
struct GpuSample {
  glm::vec4 direction_and_radius;
  std::array<glm::vec4, 4> sh_weights;
};
static_assert(sizeof(GpuSample) == 80, "std430 layout of ssrt samples");

struct SampleSetsDesc {
  uint32_t directions = 32;   // N per set, even, 8..1024
  uint32_t seed = 1;          // the sets are a pure function of (directions, seed)
};

struct SampleSets {
  uint32_t directions = 0;                 // N
  std::vector<GpuSample> samples;          // kJitterSets * N, set-major
  float median_neighbour_angle = 0.0f;     // radians, over the Delaunay edges of all sets
  float chi = 0.0f;                        // eq. 9 (see transfer_math.h for the reading used)
};

// Jittered stratified directions: set k places sample i < N/2 in the i-th equal-area band of
// the upper hemisphere (z jittered inside a band of height 2/N, a spherical Fibonacci spiral in
// azimuth with a random phase per set) and its antipode at i + N/2, so every set covers the
// sphere evenly and the four sets of a 2x2 block interleave. BadUsage when `directions` is out of range.
Expected<SampleSets> make_sample_sets(const SampleSetsDesc& desc);

// Spherical Delaunay triangulation of unit vectors = their convex hull (every point lies on the
// sphere). Returns the triangles (indices, outward counter-clockwise). BadInput when fewer than
// 4 points or all points coplanar.
Expected<std::vector<std::array<uint32_t, 3>>> spherical_delaunay(
    const std::vector<glm::dvec3>& points);

// Median over the triangulation's unique edges of the angle between their endpoints, radians.
double median_edge_angle(const std::vector<glm::dvec3>& points,
                         const std::vector<std::array<uint32_t, 3>>& triangles);

}  // namespace mrgi::ssrt
