#include "technique/ssrt/sample_directions.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "shared/transfer_math.h"
#include "light/sh_tools.h"

namespace mrgi::ssrt {
using light::kPi;
using light::ShVector;
using light::sh_basis;
namespace {

uint64_t edge_key(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

}  // namespace

Expected<std::vector<std::array<uint32_t, 3>>> spherical_delaunay(
    const std::vector<glm::dvec3>& points) {
  using Tri = std::array<uint32_t, 3>;
  const size_t n = points.size();
  if (n < 4) {
    return fail(ErrorKind::BadInput, "ssrt spherical_delaunay: " + std::to_string(n) +
                                         " points, a triangulation needs at least 4");
  }
  // Initial tetrahedron: 0, the farthest from 0, the farthest from their line, the farthest from
  // their plane.
  uint32_t i1 = 1;
  for (uint32_t i = 1; i < n; ++i)
    if (glm::distance(points[i], points[0]) > glm::distance(points[i1], points[0])) i1 = i;
  uint32_t i2 = UINT32_MAX;
  double best = 1e-9;
  for (uint32_t i = 0; i < n; ++i) {
    const double a = glm::length(glm::cross(points[i1] - points[0], points[i] - points[0]));
    if (a > best) best = a, i2 = i;
  }
  uint32_t i3 = UINT32_MAX;
  best = 1e-9;
  glm::dvec3 plane_n(0.0);
  if (i2 != UINT32_MAX) {
    plane_n = glm::cross(points[i1] - points[0], points[i2] - points[0]);
    for (uint32_t i = 0; i < n; ++i) {
      const double h = std::abs(glm::dot(plane_n, points[i] - points[0]));
      if (h > best) best = h, i3 = i;
    }
  }
  if (i3 == UINT32_MAX) {
    return fail(ErrorKind::BadInput,
                "ssrt spherical_delaunay: the points are collinear or coplanar, no hull");
  }
  auto normal_of = [&](const Tri& t) {
    return glm::cross(points[t[1]] - points[t[0]], points[t[2]] - points[t[0]]);
  };
  std::vector<Tri> faces;
  const uint32_t base[4] = {0, i1, i2, i3};
  const glm::dvec3 centre = (points[0] + points[i1] + points[i2] + points[i3]) * 0.25;
  for (int f = 0; f < 4; ++f) {
    Tri t{base[(f + 1) % 4], base[(f + 2) % 4], base[(f + 3) % 4]};
    if (glm::dot(normal_of(t), points[t[0]] - centre) < 0.0) std::swap(t[1], t[2]);
    faces.push_back(t);
  }
  std::vector<Tri> kept;
  std::unordered_set<uint64_t> visible_edges;
  for (uint32_t p = 0; p < n; ++p) {
    if (p == 0 || p == i1 || p == i2 || p == i3) continue;
    kept.clear();
    visible_edges.clear();
    std::vector<Tri> visible;
    for (const Tri& t : faces) {
      const glm::dvec3 nrm = normal_of(t);
      const double scale = glm::length(nrm);
      if (glm::dot(nrm, points[p] - points[t[0]]) > 1e-12 * scale) {
        visible.push_back(t);
        for (int e = 0; e < 3; ++e) visible_edges.insert(edge_key(t[e], t[(e + 1) % 3]));
      } else {
        kept.push_back(t);
      }
    }
    if (visible.empty()) continue;  // inside the hull (duplicate point): not a vertex
    // Horizon: directed edges of visible faces whose reverse belongs to a face that stays.
    for (const Tri& t : visible) {
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t[e], b = t[(e + 1) % 3];
        if (!visible_edges.count(edge_key(b, a))) kept.push_back(Tri{a, b, p});
      }
    }
    faces.swap(kept);
  }
  return faces;
}

double median_edge_angle(const std::vector<glm::dvec3>& points,
                         const std::vector<std::array<uint32_t, 3>>& triangles) {
  std::unordered_set<uint64_t> seen;
  std::vector<double> angles;
  for (const auto& t : triangles) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = std::min(t[e], t[(e + 1) % 3]), b = std::max(t[e], t[(e + 1) % 3]);
      if (!seen.insert(edge_key(a, b)).second) continue;
      const double c = glm::dot(glm::normalize(points[a]), glm::normalize(points[b]));
      angles.push_back(std::acos(std::clamp(c, -1.0, 1.0)));
    }
  }
  if (angles.empty()) return 0.0;
  const size_t mid = angles.size() / 2;
  std::nth_element(angles.begin(), angles.begin() + mid, angles.end());
  return angles[mid];
}

Expected<SampleSets> make_sample_sets(const SampleSetsDesc& desc) {
  if (desc.directions < 8 || desc.directions > 1024 || desc.directions % 2 != 0) {
    return fail(ErrorKind::BadUsage, "ssrt sample directions: N = " +
                                         std::to_string(desc.directions) +
                                         " must be even (antipodal pairs) and in 8..1024");
  }
  const uint32_t n = desc.directions;
  SampleSets out;
  out.directions = n;
  out.samples.resize(size_t(kJitterSets) * n);
  std::mt19937 rng(desc.seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  const double solid_angle = 4.0 * kPi / n;
  std::vector<double> medians;
  for (int set = 0; set < kJitterSets; ++set) {
    std::vector<glm::dvec3> dirs(n);
    const double phase = 2.0 * kPi * uni(rng);
    const uint32_t half = n / 2;
    for (uint32_t i = 0; i < half; ++i) {
      // Upper hemisphere, jittered inside equal-area z strata, spiral in azimuth; the lower half
      // holds the antipodes (antithetic pairs), so every odd SH band integrates to exactly 0
      // and any pixel's hemisphere holds exactly N/2 directions.
      const double z = 1.0 - (i + uni(rng)) / half;
      const double phi = phase + golden_angle * i + (uni(rng) - 0.5) * 0.25 * golden_angle;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      dirs[i] = glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
      dirs[i + half] = -dirs[i];
    }
    for (uint32_t i = 0; i < n; ++i) {
      // SSDO's random displacement along w: fractions of the radius, never 0, spread evenly so
      // near and far occluders are both seen (Ritschel et al. 2009 sample in the ball).
      const double radius = std::max(0.05, std::sqrt(uni(rng)));
      GpuSample& s = out.samples[size_t(set) * n + i];
      s.direction_and_radius = glm::vec4(glm::vec3(dirs[i]), float(radius));
      const ShVector y = sh_basis(glm::vec3(dirs[i]));
      for (int k = 0; k < 4; ++k) {
        s.sh_weights[k] = glm::vec4(y[4 * k], y[4 * k + 1], y[4 * k + 2], y[4 * k + 3]) *
                          float(solid_angle);
      }
    }
    auto tris = spherical_delaunay(dirs);
    if (!tris.ok()) return tris.error();
    medians.push_back(median_edge_angle(dirs, *tris));
  }
  std::sort(medians.begin(), medians.end());
  out.median_neighbour_angle = float(0.5 * (medians[1] + medians[2]));
  out.chi = shader::ssrt_chi_from_median_angle(out.median_neighbour_angle);
  return out;
}

}  // namespace mrgi::ssrt
