// Sphere proxies of a mesh's solid (runtime/src/frame/occluder_spheres.h): they stay inside the
// solid they stand for, fill most of it, come most important first, and refuse nothing silently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "frame/occluder_spheres.h"
#include "mrgi/scene.h"
#include "test_meshes.h"

namespace {
using mrgi::frame::fit_occluder_spheres;
using mrgi::frame::occluder_coverage;

using Mesh = mrgi::test::TestMesh;
Mesh box(glm::vec3 lo, glm::vec3 hi) { return mrgi::test::box_mesh(lo, hi); }
Mesh uv_sphere(glm::vec3 c, float r) { return mrgi::test::uv_sphere_mesh(c, r); }

TEST(OccluderSpheres, ASphereIsFittedByOneSphereOfItsSize) {
  const Mesh m = uv_sphere(glm::vec3(0.2f, 1.0f, -0.5f), 0.3f);
  const auto s = fit_occluder_spheres(m.p, m.i);
  ASSERT_FALSE(s.empty());
  EXPECT_NEAR(s[0].x, 0.2f, 0.03f);
  EXPECT_NEAR(s[0].y, 1.0f, 0.03f);
  EXPECT_NEAR(s[0].z, -0.5f, 0.03f);
  EXPECT_NEAR(s[0].w, 0.3f, 0.03f);  // within a voxel (0.6 / 24 = 0.025 m)
  EXPECT_GT(occluder_coverage(m.p, m.i, {s[0]}), 0.85);
}

TEST(OccluderSpheres, ABoxIsFilledBySpheresInsideIt) {
  const glm::vec3 lo(-0.5f, 0.0f, -0.1f), hi(0.5f, 0.2f, 0.1f);
  const Mesh m = box(lo, hi);
  const auto s = fit_occluder_spheres(m.p, m.i);
  ASSERT_GE(s.size(), 3u);  // a 5:1:1 box is not one sphere
  for (const glm::vec4& q : s) {
    // Inscribed: no sphere reaches more than a voxel (1/24 m) beyond the box.
    EXPECT_LE(q.x + q.w, hi.x + 0.045f);
    EXPECT_GE(q.x - q.w, lo.x - 0.045f);
    EXPECT_LE(q.y + q.w, hi.y + 0.045f);
    EXPECT_GE(q.y - q.w, lo.y - 0.045f);
  }
  // Inscribed spheres cannot fill a box's edges: a square's inscribed circle is pi / 4 of it.
  const double all = occluder_coverage(m.p, m.i, s);
  EXPECT_GT(all, 0.72);
  // The first spheres matter most: half the list covers more than half of what all of it does.
  const std::vector<glm::vec4> half(s.begin(), s.begin() + std::ptrdiff_t(s.size() / 2));
  EXPECT_GT(occluder_coverage(m.p, m.i, half), 0.5 * all);
  // More spheres allowed, at least as good.
  mrgi::frame::OccluderFitSettings few;
  few.max_spheres = 2;
  EXPECT_LE(fit_occluder_spheres(m.p, m.i, few).size(), 2u);
  EXPECT_LE(occluder_coverage(m.p, m.i, fit_occluder_spheres(m.p, m.i, few)), all + 1e-9);
}

TEST(OccluderSpheres, AMeshOpenAtItsBaseIsStillASolid) {
  // A sphere without its bottom cap (as a scanned object standing on a table): the hole is far
  // larger than a voxel, yet the fit is the sphere, not a shell of thin spheres.
  const Mesh whole = uv_sphere(glm::vec3(0.0f), 0.3f);
  Mesh open = whole;
  open.i.clear();
  for (size_t t = 0; t + 2 < whole.i.size(); t += 3) {
    const float lowest = std::min({whole.p[whole.i[t]].y, whole.p[whole.i[t + 1]].y, whole.p[whole.i[t + 2]].y});
    if (lowest > -0.2f) open.i.insert(open.i.end(), {whole.i[t], whole.i[t + 1], whole.i[t + 2]});
  }
  ASSERT_LT(open.i.size(), whole.i.size());
  const auto s = fit_occluder_spheres(open.p, open.i);
  ASSERT_FALSE(s.empty());
  EXPECT_GT(s[0].w, 0.2f);
}

TEST(OccluderSpheres, NothingToFitGivesNoSpheres) {
  EXPECT_TRUE(fit_occluder_spheres({}, {}).empty());
  // One point repeated: no extent.
  EXPECT_TRUE(fit_occluder_spheres({glm::vec3(1.0f)}, {0, 0, 0}).empty());
  // Indices out of range are skipped, not read.
  EXPECT_TRUE(fit_occluder_spheres({glm::vec3(0.0f)}, {0, 7, 9}).empty());
  // NaN positions are skipped too.
  Mesh m = box(glm::vec3(0.0f), glm::vec3(0.1f));
  m.p.push_back(glm::vec3(std::nanf("")));
  m.i.insert(m.i.end(), {0, 1, 8});
  const auto s = fit_occluder_spheres(m.p, m.i);
  ASSERT_FALSE(s.empty());
  for (const glm::vec4& q : s) EXPECT_TRUE(std::isfinite(q.x) && std::isfinite(q.w));
}

TEST(OccluderSpheres, AnOpenSheetKeepsOnlyThinSpheres) {
  // A single square (no volume): the shell alone, spheres of about half a voxel.
  Mesh m;
  m.p = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  m.i = {0, 1, 2, 0, 2, 3};
  const auto s = fit_occluder_spheres(m.p, m.i);
  ASSERT_FALSE(s.empty());
  for (const glm::vec4& q : s) EXPECT_LE(q.w, 1.0f / 24.0f);
}

// The fit sums distant groups of triangles by their first-order term (fast winding numbers);
// the reference path sums every triangle at every voxel. They must classify every voxel alike,
// so give the same spheres: on closed and open meshes, a flat bar, and the sample's scanned
// bunny (open at its base, 1500 triangles after simplification).
TEST(OccluderSpheres, TheTreeWindingFitsWhatTheExactSumFits) {
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.emplace_back("sphere", uv_sphere(glm::vec3(0.2f, 1.0f, -0.5f), 0.3f));
  meshes.emplace_back("bar", box(glm::vec3(-0.5f, 0.0f, -0.1f), glm::vec3(0.5f, 0.2f, 0.1f)));
  Mesh open = uv_sphere(glm::vec3(0.0f), 0.3f);
  std::vector<uint32_t> kept;
  for (size_t t = 0; t + 2 < open.i.size(); t += 3)
    if (std::min({open.p[open.i[t]].y, open.p[open.i[t + 1]].y, open.p[open.i[t + 2]].y}) > -0.2f)
      kept.insert(kept.end(), {open.i[t], open.i[t + 1], open.i[t + 2]});
  open.i = kept;
  meshes.emplace_back("open sphere", open);
  auto bunny = mrgi::load_gltf(std::string(MRGI_SOURCE_DIR) + "/data/sample/virtual/0_bunny.glb", mrgi::Placement{});
  ASSERT_TRUE(bunny.ok()) << bunny.error().message;
  for (const mrgi::MeshPrimitive& prim : bunny->primitives) meshes.emplace_back("bunny", Mesh{prim.positions, prim.indices});
  mrgi::frame::OccluderFitSettings exact;
  exact.exact_winding = true;
  for (const auto& [name, m] : meshes) {
    const auto fast = fit_occluder_spheres(m.p, m.i);
    const auto reference = fit_occluder_spheres(m.p, m.i, exact);
    ASSERT_EQ(fast.size(), reference.size()) << name;
    for (size_t k = 0; k < fast.size(); ++k) EXPECT_EQ(fast[k], reference[k]) << name << " sphere " << k;
  }
}

}  // namespace
