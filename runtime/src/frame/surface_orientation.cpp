#include "frame/surface_orientation.h"

#include <algorithm>
#include <cmath>

namespace mrgi::frame {
namespace {

// Area-weighted sums of the triangles gathered so far in one bin or patch.
struct Accumulator {
  glm::dvec3 normal_area{0.0};  // sum of unit normal x area
  double area = 0.0;
  glm::dvec3 albedo_area{0.0};
  void add(const Accumulator& o) {
    normal_area += o.normal_area;
    area += o.area;
    albedo_area += o.albedo_area;
  }
  glm::dvec3 mean_normal() const {
    const double l = glm::length(normal_area);
    return l > 1e-12 ? normal_area / l : glm::dvec3(0.0, 1.0, 0.0);
  }
};

// The k-th of `count` directions spread evenly over the sphere (spherical Fibonacci).
glm::dvec3 fibonacci(int k, int count) {
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  const double y = 1.0 - (k + 0.5) * 2.0 / count;
  const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
  return {r * std::cos(golden * k), y, r * std::sin(golden * k)};
}

constexpr int kBins = 128;

// The triangles' histogram over kBins directions (each bin's mean normal is its triangles' own,
// not the bin's centre, so flat faces stay exact).
std::vector<Accumulator> histogram(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                                   const std::vector<glm::vec3>& triangle_albedo) {
  std::vector<glm::dvec3> dirs(kBins);
  for (int k = 0; k < kBins; ++k) dirs[size_t(k)] = fibonacci(k, kBins);
  std::vector<Accumulator> bins(kBins);
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t i0 = indices[t], i1 = indices[t + 1], i2 = indices[t + 2];
    if (i0 >= positions.size() || i1 >= positions.size() || i2 >= positions.size()) continue;
    const glm::dvec3 c = glm::cross(glm::dvec3(positions[i1] - positions[i0]), glm::dvec3(positions[i2] - positions[i0]));
    const double twice = glm::length(c);
    if (!(twice > 1e-20) || !std::isfinite(twice)) continue;
    const glm::dvec3 n = c / twice;
    int best = 0;
    double best_dot = -2.0;
    for (int k = 0; k < kBins; ++k) {
      const double d = glm::dot(n, dirs[size_t(k)]);
      if (d > best_dot) best_dot = d, best = k;
    }
    const double area = 0.5 * twice;
    const size_t tri = t / 3;
    const glm::dvec3 albedo = tri < triangle_albedo.size() ? glm::dvec3(triangle_albedo[tri]) : glm::dvec3(0.0);
    Accumulator& b = bins[size_t(best)];
    b.normal_area += n * area;
    b.area += area;
    b.albedo_area += albedo * area;
  }
  bins.erase(std::remove_if(bins.begin(), bins.end(), [](const Accumulator& b) { return !(b.area > 0.0); }), bins.end());
  return bins;
}

}  // namespace

std::vector<OrientedPatch> cluster_surface_orientations(const std::vector<glm::vec3>& positions,
                                                        const std::vector<uint32_t>& indices,
                                                        const std::vector<glm::vec3>& triangle_albedo,
                                                        int max_patches) {
  const std::vector<Accumulator> bins = histogram(positions, indices, triangle_albedo);
  if (bins.empty()) return {};
  const int k_max = std::clamp(max_patches, 1, 64);
  // Seeds farthest-first: the heaviest bin, then repeatedly the bin whose normal is farthest
  // from every seed so far (area-weighted, so a sliver of odd triangles does not take a seed),
  // stopping early where every bin lies within a degree of a seed.
  std::vector<glm::dvec3> seeds{std::max_element(bins.begin(), bins.end(), [](const Accumulator& a, const Accumulator& b) {
                                  return a.area < b.area;
                                })->mean_normal()};
  std::vector<double> nearest(bins.size(), 2.0);  // 1 - cos to the nearest seed
  while (int(seeds.size()) < k_max) {
    double best = -1.0;
    size_t pick = 0;
    for (size_t b = 0; b < bins.size(); ++b) {
      nearest[b] = std::min(nearest[b], 1.0 - glm::dot(bins[b].mean_normal(), seeds.back()));
      const double score = nearest[b] * bins[b].area;
      if (score > best) best = score, pick = b;
    }
    if (!(nearest[pick] > 1.5e-4)) break;  // cos(1 degree)
    seeds.push_back(bins[pick].mean_normal());
  }
  // Spherical k-means over the bins.
  std::vector<Accumulator> patches;
  for (int iteration = 0; iteration < 12; ++iteration) {
    patches.assign(seeds.size(), Accumulator{});
    for (const Accumulator& b : bins) {
      const glm::dvec3 n = b.mean_normal();
      size_t best = 0;
      for (size_t s = 1; s < seeds.size(); ++s)
        if (glm::dot(n, seeds[s]) > glm::dot(n, seeds[best])) best = s;
      patches[best].add(b);
    }
    for (size_t s = 0; s < seeds.size(); ++s)
      if (patches[s].area > 0.0) seeds[s] = patches[s].mean_normal();
  }
  std::vector<OrientedPatch> out;
  for (const Accumulator& p : patches) {
    if (!(p.area > 0.0)) continue;
    out.push_back({glm::vec3(p.mean_normal()), float(p.area), glm::vec3(p.albedo_area / p.area),
                   float(glm::length(p.normal_area))});
  }
  std::sort(out.begin(), out.end(), [](const OrientedPatch& a, const OrientedPatch& b) { return a.area > b.area; });
  return out;
}

}  // namespace mrgi::frame
