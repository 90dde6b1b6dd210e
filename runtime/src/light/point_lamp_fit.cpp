#include "light/point_lamp_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "light/sh_tools.h"

namespace mrgi::light {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double luminance_of(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// The lamp's geometric term at a sample: max(0, n . (x - p)) / |x - p|^3, or max(0, n . d).
double lamp_term(bool point, const glm::dvec3& at, const glm::dvec3& p, const glm::dvec3& n) {
  if (!point) return std::max(0.0, glm::dot(n, at));
  const glm::dvec3 v = at - p;
  const double d = std::max(glm::length(v), kMinLampDistance);
  return std::max(0.0, glm::dot(n, v)) / (d * d * d);
}

}  // namespace

PointLampFitter::PointLampFitter(const PointLampFitSettings& s) : settings_(s) {
  const size_t most = size_t(std::max(64, s.max_samples));
  rows_.reserve(most);
  residual_point_.reserve(most);
  residual_distant_.reserve(most);
  scratch_.reserve(most);
  constexpr int kDirections = 128;
  for (int k = 0; k < kDirections; ++k) {
    const glm::dvec3 d = fibonacci_direction(k, kDirections);
    if (d.y > -0.2) directions_.push_back(d);
  }
}

double PointLampFitter::solve(bool point, const glm::dvec3& at, double* coeffs) const {
  Eigen::Matrix<double, 5, 5> ata = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> aty = Eigen::Matrix<double, 5, 1>::Zero();
  double yy = 0.0;
  for (const Row& r : rows_) {
    if (!r.in) continue;
    const Eigen::Matrix<double, 5, 1> f(lamp_term(point, at, r.p, r.n), 1.0, r.n.x, r.n.y, r.n.z);
    ata.selfadjointView<Eigen::Lower>().rankUpdate(f);
    aty += f * r.y;
    yy += r.y * r.y;
  }
  ata = ata.selfadjointView<Eigen::Lower>();
  if (!(ata(0, 0) > 0.0)) return kInf;  // the lamp reaches no sample
  ata.diagonal().array() += 1e-9 * ata.trace();
  const Eigen::Matrix<double, 5, 1> beta = ata.ldlt().solve(aty);
  if (!beta.allFinite() || !(beta(0) > 0.0)) return kInf;  // a lamp adds light
  if (coeffs)
    for (int i = 0; i < 5; ++i) coeffs[i] = beta(i);
  return std::max(0.0, yy - beta.dot(aty));
}

double PointLampFitter::best_point(glm::dvec3& x, double& k, bool search) {
  const int g = settings_.grid, gy = std::max(2, settings_.grid - 2);
  double best = search ? kInf : solve(true, x, nullptr), c[5];
  for (int iy = 0; iy < gy && search; ++iy)
    for (int iz = 0; iz < g; ++iz)
      for (int ix = 0; ix < g; ++ix) {
        const glm::dvec3 at(lo_.x + (hi_.x - lo_.x) * ix / (g - 1), lo_.y + (hi_.y - lo_.y) * iy / (gy - 1),
                            lo_.z + (hi_.z - lo_.z) * iz / (g - 1));
        if (const double e = solve(true, at, c); e < best) {
          best = e;
          x = at;
          k = c[0];
        }
      }
  if (!std::isfinite(best)) return best;
  // Refine: three rounds of the 27 neighbours at half the step each time.
  glm::dvec3 step((hi_.x - lo_.x) / (g - 1), (hi_.y - lo_.y) / (gy - 1), (hi_.z - lo_.z) / (g - 1));
  for (int round = 0; round < 3; ++round) {
    step *= 0.5;
    const glm::dvec3 centre = x;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz)
        for (int dx = -1; dx <= 1; ++dx) {
          const glm::dvec3 at = glm::clamp(centre + step * glm::dvec3(dx, dy, dz), lo_, hi_);
          if (const double e = solve(true, at, c); e < best) {
            best = e;
            x = at;
            k = c[0];
          }
        }
  }
  return best;
}

double PointLampFitter::best_distant(glm::dvec3& d, double& k, bool search) {
  double best = search ? kInf : solve(false, d, nullptr), c[5];
  for (size_t i = 0; i < directions_.size() && search; ++i)
    if (const double e = solve(false, directions_[i], c); e < best) {
      best = e;
      d = directions_[i];
      k = c[0];
    }
  if (!std::isfinite(best)) return best;
  double spread = 0.15;  // radians, about the candidates' spacing
  for (int round = 0; round < 3; ++round, spread *= 0.5) {
    const glm::dvec3 centre = d;
    const glm::dvec3 t = glm::normalize(glm::cross(centre, std::abs(centre.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
    const glm::dvec3 b = glm::cross(centre, t);
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        const glm::dvec3 w = glm::normalize(centre + spread * (double(i) * t + double(j) * b));
        if (const double e = solve(false, w, c); e < best) {
          best = e;
          d = w;
          k = c[0];
        }
      }
  }
  return best;
}

PointLampFit PointLampFitter::fit(const RadianceSamples& store, const glm::dvec3& albedo) {
  rows_.clear();
  const auto& all = store.samples();
  size_t unclipped = 0;
  for (const auto& s : all) unclipped += s.clipped ? 0 : 1;
  if (!settings_.enabled || int(unclipped) < settings_.min_samples) return PointLampFit{};
  const size_t stride = std::max<size_t>(1, (unclipped + size_t(settings_.max_samples) - 1) / size_t(settings_.max_samples));
  size_t k = 0;
  glm::dvec3 lo(kInf), hi(-kInf);
  for (const auto& s : all) {
    if (s.clipped || (k++ % stride) != 0) continue;
    const double len = glm::length(glm::dvec3(s.normal));
    if (!(len > 0.5)) continue;
    const glm::dvec3 p(s.position);
    rows_.push_back({p, glm::dvec3(s.normal) / len, s.colour, luminance_of(s.colour), true});
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return fit_rows(albedo, lo, hi);
}

PointLampFit PointLampFitter::fit(const std::vector<LampFitSample>& samples, const glm::dvec3& albedo) {
  rows_.clear();
  if (!settings_.enabled || int(samples.size()) < settings_.min_samples) return PointLampFit{};
  const size_t stride = std::max<size_t>(1, (samples.size() + size_t(settings_.max_samples) - 1) / size_t(settings_.max_samples));
  glm::dvec3 lo(kInf), hi(-kInf);
  for (size_t i = 0; i < samples.size(); i += stride) {
    const LampFitSample& s = samples[i];
    rows_.push_back({s.position, s.normal, s.colour, luminance_of(s.colour), true});
    lo = glm::min(lo, s.position);
    hi = glm::max(hi, s.position);
  }
  return fit_rows(albedo, lo, hi);
}

PointLampFit PointLampFitter::fit_rows(const glm::dvec3& albedo, const glm::dvec3& lo, const glm::dvec3& hi) {
  PointLampFit out;
  if (!(glm::min(albedo.x, glm::min(albedo.y, albedo.z)) > 0.0)) return out;
  if (int(rows_.size()) < settings_.min_samples) return out;
  lo_ = glm::dvec3(lo.x - settings_.margin_m, lo.y + 0.3, lo.z - settings_.margin_m);
  hi_ = glm::dvec3(hi.x + settings_.margin_m, hi.y + settings_.height_m, hi.z + settings_.margin_m);

  glm::dvec3 x(0.0), d(0.0, 1.0, 0.0);
  double kp = 0.0, kd = 0.0;
  double ep = best_point(x, kp, true), ed = best_distant(d, kd, true);
  if (!std::isfinite(ep) || !std::isfinite(ed)) return out;
  // Shadowed samples out of both fits (see the header), then both again.
  std::vector<double>& rp = residual_point_;
  std::vector<double>& rd = residual_distant_;
  rp.clear();
  rd.clear();
  double cp[5], cd[5];
  solve(true, x, cp);
  solve(false, d, cd);
  auto predict = [](const double* c, double g, const glm::dvec3& n) { return c[0] * g + c[1] + c[2] * n.x + c[3] * n.y + c[4] * n.z; };
  for (const Row& r : rows_) {
    rp.push_back(r.y - predict(cp, lamp_term(true, x, r.p, r.n), r.n));
    rd.push_back(r.y - predict(cd, lamp_term(false, d, r.p, r.n), r.n));
  }
  auto mad = [&v = scratch_](const std::vector<double>& from) {  // 1.4826 x the median absolute deviation
    v.assign(from.begin(), from.end());
    std::nth_element(v.begin(), v.begin() + ptrdiff_t(v.size() / 2), v.end());
    const double med = v[v.size() / 2];
    for (double& e : v) e = std::abs(e - med);
    std::nth_element(v.begin(), v.begin() + ptrdiff_t(v.size() / 2), v.end());
    return 1.4826 * v[v.size() / 2];
  };
  const double sp = 3.0 * mad(rp), sd = 3.0 * mad(rd);
  int inliers = 0;
  for (size_t i = 0; i < rows_.size(); ++i) {
    rows_[i].in = rp[i] >= -sp && rd[i] >= -sd;
    inliers += rows_[i].in ? 1 : 0;
  }
  if (inliers < settings_.min_samples) return out;
  // Without the shadowed samples each model moves little: refined around its first fit.
  ep = best_point(x, kp, false);
  ed = best_distant(d, kd, false);
  out.residual_point = ep;
  out.residual_distant = ed;
  out.inliers = inliers;
  const double eps = 1e-6;
  const bool inside = x.x > lo_.x + eps && x.x < hi_.x - eps && x.z > lo_.z + eps && x.z < hi_.z - eps && x.y < hi_.y - eps;
  if (!std::isfinite(ep) || !(ep <= (1.0 - settings_.min_gain) * ed) || !inside) return out;
  // The lamp's colour: the same fit per channel at the found position.
  for (int ch = 0; ch < 3; ++ch) {
    for (Row& r : rows_) r.y = r.c[ch];
    double c[5] = {0, 0, 0, 0, 0};
    if (std::isfinite(solve(true, x, c))) out.intensity[ch] = kPi * c[0] / albedo[ch];
  }
  out.found = luminance_of(out.intensity) > 0.0;
  out.position = x;
  return out;
}

}  // namespace mrgi::light
