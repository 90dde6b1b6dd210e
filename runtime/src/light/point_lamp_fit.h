// A near lamp found from the views a user swept (the probeless source's store,
// radiance_samples.h). The SH estimate models every light as distant: right for the sun or a
// window, but a lamp a metre from the table lights each surface from a different direction, and
// one view's distant fit tilts towards the normals it shows (a point lamp beside a corner: 40-57
// degrees off at the object). With surfaces seen from many views at known world positions, the
// lamp's position is observable: irradiance falls off with distance and turns with the
// direction to it across the floor, the table and the walls.
//
// The fit, on the samples' luminance y (unclipped samples, at most `max_samples`, strided):
//   point    y = K max(0, n . (x - p)) / |x - p|^3 + b0 + b . n   over candidate positions x
//   distant  y = K max(0, n . d) + b0 + b . n                     over candidate directions d
// (the linear ambient b0 + b . n is the irradiance of SH bands 0-1). Each candidate is a 5x5
// linear least-squares solve; the best of each model is refined on a finer grid around it.
// Samples in the lamp's shadow are far darker than either model predicts: after a first fit,
// samples below either model's prediction by more than 3 robust standard deviations (1.4826
// MAD) are left out of both, and both are fitted again. The point lamp is taken when its
// residual is at most (1 - min_gain) of the distant light's, it lies inside the searched box
// (not on its outer faces, where a distant light would be pushed), and K > 0.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "light/radiance_samples.h"

namespace mrgi::light {

struct PointLampFitSettings {
  bool enabled = true;
  int max_samples = 160;       // samples the search reads (strided over the store), 64..65536
  double margin_m = 1.0;       // candidates reach this far beyond the samples' horizontal bounds
  double height_m = 2.0;       // ... and from 0.1 m to this far above the highest sample
  int grid = 6;                // candidate positions per horizontal axis (height: grid - 2), 4..32
  double min_gain = 0.5;       // the point lamp's residual at most (1 - this) of the distant light's
  int min_samples = 64;        // fewer unclipped samples: no fit
};

// Nearer than this (metres) a lamp's fall-off is held: a candidate next to a sample does not
// spike on it.
constexpr double kMinLampDistance = 0.15;

// A surface sample as the fit reads it: world position (metres), unit normal, linear colour.
struct LampFitSample {
  glm::dvec3 position, normal, colour;
};

struct PointLampFit {
  bool found = false;
  glm::dvec3 position{0.0};    // world, metres
  glm::dvec3 intensity{0.0};   // radiant intensity, linear RGB per channel (W/sr over the exposure)
  double residual_point = 0.0, residual_distant = 0.0;  // sums of squares over the inliers
  int inliers = 0;
};

class PointLampFitter {
 public:
  explicit PointLampFitter(const PointLampFitSettings& settings);
  // `albedo`: the surfaces' albedo per channel the estimate assumes (y = albedo / pi * E).
  // Over the store's unclipped samples (strided to max_samples):
  PointLampFit fit(const RadianceSamples& store, const glm::dvec3& albedo);
  // Over given samples (strided to max_samples): the stage's with the light the surfaces
  // bounce onto each other taken off (albedo_fit.h), so the lamp is fitted to the light it gives
  // directly (with that bounce in, a white corner's lamp came out higher and paler).
  PointLampFit fit(const std::vector<LampFitSample>& samples, const glm::dvec3& albedo);
  const PointLampFitSettings& settings() const { return settings_; }

 private:
  struct Row {
    glm::dvec3 p, n, c;
    double y;
    bool in;
  };
  // Best candidate of one model over `rows` (in ones only): returns its sum of squares and
  // writes its parameters; point model when `point`, else the direction `d` is the candidate.
  // `search`: over every candidate, then refined; else refined around `x` / `d` as given.
  double best_point(glm::dvec3& x, double& k, bool search);
  double best_distant(glm::dvec3& d, double& k, bool search);
  double solve(bool point, const glm::dvec3& at, double* coeffs) const;  // SSE; coeffs[5] or null
  PointLampFit fit_rows(const glm::dvec3& albedo, const glm::dvec3& lo, const glm::dvec3& hi);  // over rows_
  PointLampFitSettings settings_;
  std::vector<Row> rows_;               // reserved to max_samples, as the three below
  std::vector<double> residual_point_, residual_distant_, scratch_;  // the shadow test's
  std::vector<glm::dvec3> directions_;  // distant candidates (upper hemisphere and below)
  glm::dvec3 lo_{0.0}, hi_{0.0};        // the candidate box
};

}  // namespace mrgi::light
