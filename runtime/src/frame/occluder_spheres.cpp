#include "frame/occluder_spheres.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <meshoptimizer.h>

namespace mrgi::frame {
namespace {

// The voxelised solid of a mesh: dims with one padding voxel on each side, so the border is
// outside; `solid` 1 for surface and enclosed voxels; `radius` the inscribed radius (m) of each
// solid voxel.
struct SolidGrid {
  glm::ivec3 dims{0};
  glm::vec3 origin{0.0f};  // corner of voxel (0, 0, 0)
  float cell = 0.0f;
  std::vector<uint8_t> solid;
  std::vector<float> radius;
  size_t index(int x, int y, int z) const { return (size_t(z) * dims.y + y) * dims.x + x; }
  glm::vec3 centre(size_t i) const {
    const int x = int(i % size_t(dims.x)), y = int((i / size_t(dims.x)) % size_t(dims.y)),
              z = int(i / (size_t(dims.x) * dims.y));
    return origin + (glm::vec3(x, y, z) + 0.5f) * cell;
  }
  bool empty() const { return solid.empty(); }
};

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void mark_surface(SolidGrid& g, const std::vector<glm::vec3>& p, const std::vector<uint32_t>& idx) {
  auto mark = [&](const glm::vec3& q) {
    const glm::ivec3 v = glm::clamp(glm::ivec3(glm::floor((q - g.origin) / g.cell)), glm::ivec3(1), g.dims - 2);
    g.solid[g.index(v.x, v.y, v.z)] = 1;
  };
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    if (idx[t] >= p.size() || idx[t + 1] >= p.size() || idx[t + 2] >= p.size()) continue;
    const glm::vec3 a = p[idx[t]], b = p[idx[t + 1]], c = p[idx[t + 2]];
    if (!finite(a) || !finite(b) || !finite(c)) continue;  // a NaN vertex has no voxel
    const float edge = std::max({glm::length(b - a), glm::length(c - a), glm::length(c - b)});
    // Samples half a voxel apart, so no voxel the triangle crosses is skipped.
    const int steps = std::clamp(int(std::ceil(edge / (0.5f * g.cell))), 1, 4096);
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; i + j <= steps; ++j)
        mark(a + (b - a) * (float(i) / steps) + (c - a) * (float(j) / steps));
  }
}

// Solid angle of triangle (a, b, c) seen from the origin, signed by its winding (Van Oosterom
// & Strackee 1983).
double triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = glm::dot(a, glm::cross(b, c));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
  return 2.0 * std::atan2(num, den);
}

// Fast winding numbers (Barill et al. 2018): a binary tree over the triangles, each node with
// the sphere round its vertices and the sum of its triangles' area vectors. Seen from a point
// more than kFarRadii of its radii away, a node's triangles subtend about area . r / |r|^3 (the
// first-order term of the exact sum, r from the point to the node's area-weighted centroid); a
// nearer node opens to its children, and a leaf sums its triangles exactly.
constexpr double kFarRadii = 3.0;
constexpr uint32_t kLeafTriangles = 8;

struct WindingTree {
  struct Node {
    glm::dvec3 centre{0.0}, area{0.0};
    double radius = 0.0;
    uint32_t first = 0, count = 0;  // a leaf's triangles in `order`; count 0: an inner node
    uint32_t left = 0, right = 0;
  };
  std::vector<Node> nodes;
  std::vector<uint32_t> order;  // triangle numbers (index of its first vertex / 3), grouped by leaf
  const std::vector<glm::vec3>* p = nullptr;
  const std::vector<uint32_t>* tri = nullptr;

  glm::dvec3 vertex(uint32_t t, int k) const { return glm::dvec3((*p)[(*tri)[size_t(t) * 3 + size_t(k)]]); }

  uint32_t build(uint32_t first, uint32_t count) {
    const uint32_t at = uint32_t(nodes.size());
    nodes.emplace_back();
    Node n;
    double area_sum = 0.0;
    glm::dvec3 weighted(0.0), lo(1e300), hi(-1e300);
    for (uint32_t k = first; k < first + count; ++k) {
      const glm::dvec3 a = vertex(order[k], 0), b = vertex(order[k], 1), c = vertex(order[k], 2);
      const glm::dvec3 av = 0.5 * glm::cross(b - a, c - a);
      const double ar = glm::length(av);
      n.area += av;
      area_sum += ar;
      weighted += ar * (a + b + c) / 3.0;
      const glm::dvec3 m = (a + b + c) / 3.0;
      lo = glm::min(lo, m);
      hi = glm::max(hi, m);
    }
    n.centre = area_sum > 0.0 ? weighted / area_sum : 0.5 * (lo + hi);
    for (uint32_t k = first; k < first + count; ++k)
      for (int v = 0; v < 3; ++v) n.radius = std::max(n.radius, glm::length(vertex(order[k], v) - n.centre));
    if (count <= kLeafTriangles) {
      n.first = first;
      n.count = count;
    } else {
      // Split at the median centroid along the longest side of the centroids' bounds.
      const glm::dvec3 e = hi - lo;
      const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
      const uint32_t half = count / 2;
      auto key = [&](uint32_t t) { return vertex(t, 0)[axis] + vertex(t, 1)[axis] + vertex(t, 2)[axis]; };
      std::nth_element(order.begin() + first, order.begin() + first + half, order.begin() + first + count,
                       [&](uint32_t x, uint32_t y) { return key(x) < key(y); });
      n.left = build(first, half);
      n.right = build(first + half, count - half);
    }
    nodes[at] = n;
    return at;
  }

  // Sum of the triangles' signed solid angles seen from q (4 pi w).
  double solid_angle(const glm::dvec3& q, std::vector<uint32_t>& stack) const {
    double w = 0.0;
    stack.assign(1, 0);
    while (!stack.empty()) {
      const Node& n = nodes[stack.back()];
      stack.pop_back();
      const glm::dvec3 r = n.centre - q;
      const double d = glm::length(r);
      if (d > kFarRadii * n.radius) {
        w += glm::dot(n.area, r) / (d * d * d);
      } else if (n.count > 0) {
        for (uint32_t k = n.first; k < n.first + n.count; ++k)
          w += triangle_solid_angle(vertex(order[k], 0) - q, vertex(order[k], 1) - q, vertex(order[k], 2) - q);
      } else {
        stack.push_back(n.left);
        stack.push_back(n.right);
      }
    }
    return w;
  }

  double exact_solid_angle(const glm::dvec3& q) const {
    double w = 0.0;
    for (uint32_t t = 0; t < uint32_t(tri->size() / 3); ++t)
      w += triangle_solid_angle(vertex(t, 0) - q, vertex(t, 1) - q, vertex(t, 2) - q);
    return w;
  }
};

// Within this many steradians of the threshold (2 pi: |w| = 1/2) the tree's approximate sum is
// replaced by the exact one, so a voxel is classified as the exact sum classifies it. A node
// kept whole is off by about (radius / distance)^2 of its own solid angle; over the test meshes
// and the sample's scanned bunny the tree's sum came within 0.15 sr of the exact one at every
// voxel (tests/unit/test_occluder_spheres.cpp checks the fits agree).
constexpr double kExactBand = 1.5;

// Marks as solid every voxel whose centre the mesh winds around (generalised winding number
// |w| >= 1/2, Jacobson et al. 2013): robust to holes, which a flood fill from outside would
// leak through (scanned meshes such as the Stanford bunny are open at the base). The winding
// is summed over a simplified copy of the mesh (at most kWindingTriangles), which moves it by
// little more than the simplification's error.
constexpr size_t kWindingTriangles = 1500;
void fill_inside_by_winding(SolidGrid& g, const std::vector<glm::vec3>& p, const std::vector<uint32_t>& idx, bool exact) {
  std::vector<uint32_t> tri;
  tri.reserve(idx.size());
  for (size_t t = 0; t + 2 < idx.size(); t += 3)
    if (idx[t] < p.size() && idx[t + 1] < p.size() && idx[t + 2] < p.size() && std::isfinite(p[idx[t]].x) &&
        std::isfinite(p[idx[t + 1]].x) && std::isfinite(p[idx[t + 2]].x) && std::isfinite(p[idx[t]].y + p[idx[t]].z) &&
        std::isfinite(p[idx[t + 1]].y + p[idx[t + 1]].z) && std::isfinite(p[idx[t + 2]].y + p[idx[t + 2]].z))
      tri.insert(tri.end(), {idx[t], idx[t + 1], idx[t + 2]});
  if (tri.size() / 3 > kWindingTriangles) {
    std::vector<uint32_t> simple(tri.size());
    float error = 0.0f;
    const size_t n = meshopt_simplify(simple.data(), tri.data(), tri.size(), &p[0].x, p.size(), sizeof(glm::vec3),
                                      kWindingTriangles * 3, 0.02f, 0, &error);
    if (n >= 3) {
      simple.resize(n);
      tri.swap(simple);
    }
  }
  if (tri.empty()) return;
  WindingTree tree;
  tree.p = &p;
  tree.tri = &tri;
  tree.order.resize(tri.size() / 3);
  std::iota(tree.order.begin(), tree.order.end(), 0u);
  if (!exact) {  // the reference path sums every triangle and needs no tree
    tree.nodes.reserve(2 * tree.order.size() / kLeafTriangles + 2);
    tree.build(0, uint32_t(tree.order.size()));
  }
  constexpr double kHalf = 2.0 * 3.14159265358979;  // |w| = |sum| / 4 pi >= 1/2
  std::vector<uint32_t> stack;
  for (size_t i = 0; i < g.solid.size(); ++i) {
    if (g.solid[i]) continue;
    const glm::dvec3 c(g.centre(i));
    double w = exact ? std::abs(tree.exact_solid_angle(c)) : std::abs(tree.solid_angle(c, stack));
    if (!exact && std::abs(w - kHalf) < kExactBand) w = std::abs(tree.exact_solid_angle(c));
    if (w >= kHalf) g.solid[i] = 1;
  }
}

// Floods the outside from voxel (0, 0, 0) through non-surface voxels (6-connected); what is not
// reached becomes solid.
void fill_inside(SolidGrid& g) {
  std::vector<uint8_t> outside(g.solid.size(), 0);
  std::vector<size_t> stack{0};
  outside[0] = 1;
  const glm::ivec3 d = g.dims;
  while (!stack.empty()) {
    const size_t i = stack.back();
    stack.pop_back();
    const int x = int(i % size_t(d.x)), y = int((i / size_t(d.x)) % size_t(d.y)), z = int(i / (size_t(d.x) * d.y));
    const int n[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
    for (const auto& q : n) {
      if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= d.x || q[1] >= d.y || q[2] >= d.z) continue;
      const size_t j = g.index(q[0], q[1], q[2]);
      if (outside[j] || g.solid[j]) continue;
      outside[j] = 1;
      stack.push_back(j);
    }
  }
  for (size_t i = 0; i < g.solid.size(); ++i) g.solid[i] = outside[i] ? 0 : 1;
}

// Inscribed radius of each solid voxel: the distance from its centre to the nearest outside
// voxel's centre, less half a voxel (the surface lies between them), at least half a voxel.
void inscribed_radii(SolidGrid& g) {
  std::vector<glm::vec3> boundary;  // outside voxels with a solid 6-neighbour
  const glm::ivec3 d = g.dims;
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) {
        if (g.solid[g.index(x, y, z)]) continue;
        const int n[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
        for (const auto& q : n) {
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= d.x || q[1] >= d.y || q[2] >= d.z) continue;
          if (g.solid[g.index(q[0], q[1], q[2])]) {
            boundary.push_back(g.centre(g.index(x, y, z)));
            break;
          }
        }
      }
  g.radius.assign(g.solid.size(), 0.0f);
  for (size_t i = 0; i < g.solid.size(); ++i) {
    if (!g.solid[i]) continue;
    const glm::vec3 c = g.centre(i);
    float best = 1e30f;
    for (const glm::vec3& b : boundary) {
      const glm::vec3 e = b - c;
      best = std::min(best, glm::dot(e, e));
    }
    g.radius[i] = std::max(std::sqrt(best) - 0.5f * g.cell, 0.5f * g.cell);
  }
}

SolidGrid voxelise(const std::vector<glm::vec3>& p, const std::vector<uint32_t>& idx, int cells, bool exact_winding) {
  SolidGrid g;
  glm::vec3 lo(1e30f), hi(-1e30f);
  bool any = false;
  for (size_t t = 0; t + 2 < idx.size(); t += 3)
    for (int k = 0; k < 3; ++k)
      if (idx[t + k] < p.size() && std::isfinite(p[idx[t + k]].x) && std::isfinite(p[idx[t + k]].y) &&
          std::isfinite(p[idx[t + k]].z)) {
        lo = glm::min(lo, p[idx[t + k]]);
        hi = glm::max(hi, p[idx[t + k]]);
        any = true;
      }
  if (!any) return g;
  const glm::vec3 extent = hi - lo;
  const float longest = std::max({extent.x, extent.y, extent.z});
  if (!(longest > 0.0f)) return g;
  g.cell = longest / float(std::clamp(cells, 4, 64));
  g.dims = glm::ivec3(glm::ceil(extent / g.cell)) + 1 + 2;  // +1: a flat side still gets a layer
  g.origin = lo - g.cell * 1.0f - 0.5f * (glm::vec3(g.dims - 2) * g.cell - extent);
  g.solid.assign(size_t(g.dims.x) * g.dims.y * g.dims.z, 0);
  mark_surface(g, p, idx);
  fill_inside(g);
  fill_inside_by_winding(g, p, idx, exact_winding);
  inscribed_radii(g);
  return g;
}

bool in_sphere(const glm::vec3& q, const glm::vec4& s) {
  const glm::vec3 e = q - glm::vec3(s);
  return glm::dot(e, e) <= s.w * s.w;
}

}  // namespace

std::vector<glm::vec4> fit_occluder_spheres(const std::vector<glm::vec3>& positions,
                                            const std::vector<uint32_t>& indices,
                                            const OccluderFitSettings& settings) {
  std::vector<glm::vec4> spheres;
  SolidGrid g = voxelise(positions, indices, settings.grid_cells, settings.exact_winding);
  if (g.empty()) return spheres;
  std::vector<size_t> solid;
  for (size_t i = 0; i < g.solid.size(); ++i)
    if (g.solid[i]) solid.push_back(i);
  if (solid.empty()) return spheres;
  std::vector<uint8_t> covered(g.solid.size(), 0);
  size_t covered_count = 0;
  const int max_spheres = std::clamp(settings.max_spheres, 1, 64);
  const size_t want = size_t(std::ceil(std::clamp(settings.coverage, 0.0, 1.0) * double(solid.size())));
  std::vector<size_t> order;
  while (int(spheres.size()) < max_spheres && covered_count < want) {
    // Candidates: the uncovered solid voxels of largest inscribed radius.
    order.clear();
    for (size_t i : solid)
      if (!covered[i]) order.push_back(i);
    const size_t n = std::min(order.size(), size_t(std::max(1, settings.candidates)));
    std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(n), order.end(),
                      [&](size_t a, size_t b) { return g.radius[a] > g.radius[b]; });
    size_t best = order[0], best_gain = 0;
    for (size_t c = 0; c < n; ++c) {
      const glm::vec4 s(g.centre(order[c]), g.radius[order[c]] + 0.5f * g.cell);
      size_t gain = 0;
      for (size_t i : solid)
        if (!covered[i] && in_sphere(g.centre(i), s)) ++gain;
      if (gain > best_gain) best_gain = gain, best = order[c];
    }
    // The sphere reaches the surface (inscribed radius); voxels count as covered by their centre
    // within half a voxel more, so a one-voxel shell is covered by its own spheres.
    const glm::vec4 reach(g.centre(best), g.radius[best] + 0.5f * g.cell);
    for (size_t i : solid)
      if (!covered[i] && in_sphere(g.centre(i), reach)) covered[i] = 1, ++covered_count;
    spheres.emplace_back(g.centre(best), g.radius[best]);
  }
  return spheres;
}

double occluder_coverage(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                         const std::vector<glm::vec4>& spheres, const OccluderFitSettings& settings) {
  SolidGrid g = voxelise(positions, indices, settings.grid_cells, settings.exact_winding);
  size_t total = 0, in = 0;
  for (size_t i = 0; i < g.solid.size(); ++i) {
    if (!g.solid[i]) continue;
    ++total;
    for (const glm::vec4& s : spheres)
      if (in_sphere(g.centre(i), glm::vec4(glm::vec3(s), s.w + 0.5f * g.cell))) {
        ++in;
        break;
      }
  }
  return total ? double(in) / double(total) : 0.0;
}

}  // namespace mrgi::frame
