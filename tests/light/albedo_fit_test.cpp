// The surfaces' albedo from their interreflection (light/albedo_fit.h): a room corner whose
// samples carry the light the walls and floor bounce onto each other (computed here by brute
// force, several bounces, independently of the fitter's direction bins) gives back its albedo;
// surfaces that bounce nothing onto each other leave the grey-world prior; too few samples make
// no fit. And the near-lamp search on given samples (the stage's, with the bounce taken off)
// finds what it finds on the store's.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "light/albedo_fit.h"
#include "light/point_lamp_fit.h"
#include "light/radiance_samples.h"

namespace {
using namespace mrgi;
using namespace mrgi::light;

struct Patch {
  glm::dvec3 p, n;
  glm::dvec3 colour{0.0};
};

// A floor (2 x 2 m) and, with `walls`, a back and a left wall (2 m high), on a `cell` grid.
std::vector<Patch> corner(bool walls, double cell) {
  std::vector<Patch> out;
  const int n = int(std::lround(2.0 / cell));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = -1.0 + (i + 0.5) * cell, v = -0.5 + (j + 0.5) * cell, h = (j + 0.5) * cell;
      out.push_back({{u, 0.0, v}, {0, 1, 0}});
      if (walls) {
        out.push_back({{u, h, 1.5}, {0, 0, -1}});
        out.push_back({{-1.0, h, -0.5 + (i + 0.5) * cell}, {1, 0, 0}});
      }
    }
  return out;
}

// Each patch's radiance under a sun of irradiance `sun_e` from `sun` (nothing of the corner
// shadows it: it comes from the open side) and `bounces` bounces of the patches' own light
// (no occluder between two patches of a corner), albedo `albedo`.
void light_corner(std::vector<Patch>& patches, const glm::dvec3& sun, double sun_e, double albedo, double cell,
                  int bounces) {
  const double area = cell * cell;
  std::vector<double> direct(patches.size()), radiance(patches.size()), next(patches.size());
  for (size_t i = 0; i < patches.size(); ++i)
    direct[i] = radiance[i] = albedo / kPi * sun_e * std::max(0.0, glm::dot(patches[i].n, sun));
  for (int b = 0; b < bounces; ++b) {
    for (size_t i = 0; i < patches.size(); ++i) {
      double e = 0.0;
      for (size_t j = 0; j < patches.size(); ++j) {
        const glm::dvec3 v = patches[j].p - patches[i].p;
        const double d2 = glm::dot(v, v);
        if (d2 < 0.25 * area) continue;
        const double ci = glm::dot(patches[i].n, v), cj = -glm::dot(patches[j].n, v);
        if (ci <= 0.0 || cj <= 0.0) continue;
        e += radiance[j] * ci * cj * area / (d2 * std::max(d2, area));
      }
      next[i] = direct[i] + albedo / kPi * e;
    }
    radiance.swap(next);
  }
  for (size_t i = 0; i < patches.size(); ++i) patches[i].colour = glm::dvec3(radiance[i]);
}

RadianceSamples store_of(const std::vector<Patch>& patches, double cell) {
  RadianceSampleSettings s;
  s.cell_m = cell;
  s.capacity = 16384;
  auto store = RadianceSamples::create(s);
  EXPECT_TRUE(store.ok()) << (store.ok() ? "" : store.error().message);
  for (const Patch& p : patches) store->observe(p.p, glm::vec3(p.n), 0, ShVector{}, p.colour, 1.0f, 0);
  return std::move(*store);
}

const glm::dvec3 kSun = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));

TEST(AlbedoFit, AWhiteCornerShowsItsAlbedoInItsInterreflection) {
  constexpr double kCell = 0.06;
  for (const double albedo : {0.8, 0.3}) {
    std::vector<Patch> patches = corner(true, kCell);
    light_corner(patches, kSun, 3.0, albedo, kCell, 4);
    const RadianceSamples store = store_of(patches, kCell);
    AlbedoFitter fitter{AlbedoFitSettings{}};
    const AlbedoFit fit = fitter.fit(store, nullptr);
    ASSERT_TRUE(fit.found);
    // The fitter's direction bins and strided emitters approximate the form factors computed
    // here (0.755 for 0.8, 0.314 for 0.3).
    EXPECT_NEAR(fit.data_albedo.y, albedo, 0.06) << "standard error " << fit.data_sigma.y;
    EXPECT_LT(fit.data_sigma.y, 0.1);
    // The prior (0.5, sigma 0.15) moves a well-measured albedo little.
    EXPECT_NEAR(fit.albedo.y, albedo, 0.15);
    EXPECT_EQ(fit.albedo.x, fit.albedo.y) << "one grey albedo by default";
    EXPECT_GT(fit.bounce_share, 0.0);
    EXPECT_EQ(fitter.fitted().size(), size_t(fit.receivers));
  }
}

TEST(AlbedoFit, AFloorAloneBouncesNothingAndKeepsThePrior) {
  constexpr double kCell = 0.06;
  std::vector<Patch> patches = corner(false, kCell);
  light_corner(patches, kSun, 3.0, 0.8, kCell, 1);
  const RadianceSamples store = store_of(patches, kCell);
  AlbedoFitter fitter{AlbedoFitSettings{}};
  const AlbedoFit fit = fitter.fit(store, nullptr);
  EXPECT_FALSE(fit.found) << "data " << fit.data_albedo.y << " +- " << fit.data_sigma.y;
  EXPECT_EQ(fit.albedo.y, AlbedoFitSettings{}.prior);
  EXPECT_FALSE(fitter.fitted().empty()) << "the receivers' bounce (none) is known all the same";
}

TEST(AlbedoFit, TooFewSamplesMakeNoFitAndAFitSpreadOverStepsIsTheSame) {
  constexpr double kCell = 0.06;
  std::vector<Patch> patches = corner(true, kCell);
  light_corner(patches, kSun, 3.0, 0.7, kCell, 2);
  AlbedoFitter fitter{AlbedoFitSettings{}};
  const RadianceSamples few = store_of(std::vector<Patch>(patches.begin(), patches.begin() + 40), kCell);
  EXPECT_FALSE(fitter.begin(few));
  const AlbedoFit none = fitter.fit(few, nullptr);
  EXPECT_FALSE(none.found);
  EXPECT_EQ(none.albedo.y, AlbedoFitSettings{}.prior);

  const RadianceSamples store = store_of(patches, kCell);
  const AlbedoFit at_once = fitter.fit(store, nullptr);
  ASSERT_TRUE(fitter.begin(store));
  int steps = 1;
  while (!fitter.step()) ++steps;
  const AlbedoFit stepped = fitter.solve(nullptr);
  EXPECT_EQ(steps, (at_once.receivers + AlbedoFitSettings{}.receivers_per_step - 1) / AlbedoFitSettings{}.receivers_per_step);
  EXPECT_DOUBLE_EQ(stepped.albedo.y, at_once.albedo.y);
  fitter.restart();
  EXPECT_TRUE(fitter.fitted().empty());
  EXPECT_FALSE(fitter.busy());
}

TEST(AlbedoFit, TheNearFieldIsTheLightTheKeptSurfacesSendToAPoint) {
  // Half a metre above the middle of a 2 x 2 m floor of radiance 0.3 (the walls dark): the
  // light from below is the floor's, none arrives from above. Compared with the floor projected
  // on the same 4 SH bands (sum over l of (2l + 1) / 4 pi times the integral of L P_l, computed
  // numerically): 0.386 straight down and 0.046 straight up at 0.5 m (the band limit rings).
  constexpr double kCell = 0.06;
  std::vector<Patch> patches = corner(true, kCell);
  for (Patch& p : patches) p.colour = glm::dvec3(p.n.y > 0.5 ? 0.3 : 0.0);
  const RadianceSamples store = store_of(patches, kCell);
  AlbedoFitter fitter{AlbedoFitSettings{}};
  ShRgb near{};
  EXPECT_FALSE(fitter.near_field_at({0.0, 0.5, 0.5}, store, near)) << "no fit begun: no emitters";
  ASSERT_TRUE(fitter.begin(store));
  ASSERT_TRUE(fitter.near_field_at({0.0, 0.5, 0.5}, store, near));
  auto radiance = [&](const glm::vec3& w) {
    const ShVector y = sh_basis(w);
    double l = 0.0;
    for (int i = 0; i < kMaxShCoeffs; ++i) l += double(y[size_t(i)]) * near[size_t(i)].y;
    return l;
  };
  EXPECT_NEAR(radiance({0, -1, 0}), 0.386, 0.04);
  EXPECT_NEAR(radiance({0, 1, 0}), 0.046, 0.04);
  // Band 0: the floor, a square of half-side 1 m 0.5 m below, spans 4 asin(1 / 1.25) = 3.709 sr,
  // so the radiance averaged over the sphere is 0.3 x 3.709 / 4 pi.
  const double mean = near[0].y / std::sqrt(4.0 * kPi);
  EXPECT_NEAR(mean, 0.3 * 3.709 / (4.0 * kPi), 0.1 * 0.3 * 3.709 / (4.0 * kPi));
  // 0.1 m above it (a virtual object's centre over the table it stands on) the floor spans
  // 4 asin(1 / 1.01) = 5.721 sr, most of it in the few cells right below, each wider than a bin
  // (whole, each covered one bin: band 0 read 0.52 of this); projected, 0.268 straight down.
  ASSERT_TRUE(fitter.near_field_at({0.0, 0.1, 0.5}, store, near));
  const double close = near[0].y / std::sqrt(4.0 * kPi);
  EXPECT_NEAR(close, 0.3 * 5.721 / (4.0 * kPi), 0.1 * 0.3 * 5.721 / (4.0 * kPi));
  EXPECT_NEAR(radiance({0, -1, 0}), 0.268, 0.04);
}

TEST(AlbedoFit, TheSurfacesAroundAPointHideTheDistantLightBehindThem) {
  // A floor alone, half a metre below: of a uniform distant light (band 0) it hides the floor's
  // share of the sphere, 3.709 sr of 4 pi; from straight above the light arrives whole.
  constexpr double kCell = 0.06;
  std::vector<Patch> patches = corner(false, kCell);
  for (Patch& p : patches) p.colour = glm::dvec3(0.2);
  const RadianceSamples store = store_of(patches, kCell);
  AlbedoFitter fitter{AlbedoFitSettings{}};
  ASSERT_TRUE(fitter.begin(store));
  ShRgb near{};
  ShMatrix hidden{};
  ASSERT_TRUE(fitter.near_field_at({0.0, 0.5, 0.5}, store, near, &hidden));
  EXPECT_NEAR(hidden[0], 3.709 / (4.0 * kPi), 0.1 * 3.709 / (4.0 * kPi));
  // A light from straight up projected on the first two bands (1 + 3 cos): the floor hides
  // little of it, far less than of the uniform light.
  const ShVector up = sh_basis(glm::vec3(0, 1, 0));
  double hidden_up = 0.0, whole_up = 0.0;
  for (int i = 0; i < 4; ++i) {
    whole_up += double(up[size_t(i)]) * up[size_t(i)];
    for (int j = 0; j < 4; ++j) hidden_up += double(up[size_t(i)]) * hidden[size_t(i * kMaxShCoeffs + j)] * up[size_t(j)];
  }
  EXPECT_LT(hidden_up / whole_up, 0.5 * hidden[0]);
  // The light at the point: a uniform distant light loses the floor's share and the floor's
  // near field comes instead; a lamp among the sources (not in the distant light) stays whole.
  ShRgb distant{}, lamp{};
  distant[0] = glm::dvec3(1.0);
  lamp[0] = glm::dvec3(0.25);
  lamp[2] = glm::dvec3(0.4);  // band 1, towards +y
  ShRgb sources = distant;
  for (int i = 0; i < kMaxShCoeffs; ++i) sources[size_t(i)] += lamp[size_t(i)];
  const ShRgb at = light_at_point(sources, distant, near, hidden);
  EXPECT_NEAR(at[0].y, 1.0 * (1.0 - hidden[0]) + near[0].y + 0.25, 1e-9);
  EXPECT_NEAR(at[0].y, 1.0 - 3.709 / (4.0 * kPi) + 0.2 * 3.709 / std::sqrt(4.0 * kPi) + 0.25, 0.05);
  EXPECT_NEAR(at[2].y, 0.4 + near[2].y - hidden[2 * kMaxShCoeffs] * 1.0, 1e-9);
}

TEST(AlbedoFit, TheLampSearchOnGivenSamplesFindsWhatItFindsOnTheStore) {
  constexpr double kCell = 0.05;
  const glm::dvec3 lamp(0.3, 1.4, 0.4);
  std::vector<Patch> patches = corner(true, kCell);
  for (Patch& p : patches) {
    const glm::dvec3 v = lamp - p.p;
    const double d = glm::length(v);
    p.colour = glm::dvec3(0.5 / kPi * (0.3 + 2.0 * std::max(0.0, glm::dot(p.n, v / d)) / (d * d)));
  }
  const RadianceSamples store = store_of(patches, kCell);
  std::vector<LampFitSample> given;
  for (const auto& s : store.samples())
    if (!s.clipped) given.push_back({glm::dvec3(s.position), glm::normalize(glm::dvec3(s.normal)), s.colour});
  PointLampFitter fitter{PointLampFitSettings{}};
  const PointLampFit a = fitter.fit(store, glm::dvec3(0.5)), b = fitter.fit(given, glm::dvec3(0.5));
  ASSERT_TRUE(a.found && b.found);
  EXPECT_LT(glm::distance(a.position, lamp), 0.15);
  EXPECT_LT(glm::distance(b.position, lamp), 0.15);
  EXPECT_NEAR(b.intensity.y, 2.0, 0.3);
  EXPECT_FALSE(fitter.fit(std::vector<LampFitSample>(given.begin(), given.begin() + 10), glm::dvec3(0.5)).found);
}

}  // namespace
