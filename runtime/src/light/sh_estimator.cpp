#include "light/sh_estimator.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <string>


namespace mrgi::light {
namespace {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 16, 16>;
using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor, 16, 3>;

Status check_estimator_setting(bool ok, const char* field, const std::string& rule) {
  if (ok) return ok_status();
  return fail(ErrorKind::BadUsage,
              std::string("ssrt LightEstimatorSettings.") + field + ": " + rule);
}

// The dominant normal of the frame's pixels: the principal axis of the band-1 block of T^T T
// (T's band 1 is the visibility-weighted cosine lobe around the normal, so the block is a sum of
// n n^T), signed so that the pixels are lit from its side (T^T I_c). Zero when undefined.
// The rows that are views of the light (LightSystem::add_view) are taken out first, their
// right-hand side in the units load_system gives `atb` (divided by the albedo; luminance for
// white light).
glm::dvec3 dominant_surface_normal(const Mat& ata, const Rhs& atb, const LightSystem& system, const glm::dvec3& albedo,
                                   bool white_light) {
  Eigen::Matrix3d b = ata.block(1, 1, 3, 3);
  Eigen::Vector3d side = atb.block(1, 0, 3, 1);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) b(i, j) -= system.view_ata1[size_t(i * 3 + j)];
    const glm::dvec3 v = glm::dvec3(system.view_atb1[size_t(i * 3)], system.view_atb1[size_t(i * 3 + 1)],
                                    system.view_atb1[size_t(i * 3 + 2)]) / albedo;
    side(i) -= white_light ? luminance(v) : v.x;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(b);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(2) > 0.0)) return glm::dvec3(0.0);
  Eigen::Vector3d e = eig.eigenvectors().col(2);
  if (e.dot(side) < 0.0) e = -e;
  // Band 1 in Sloan order is c * (-y, z, -x).
  const glm::dvec3 n(-e(2), -e(0), e(1));
  const double len = glm::length(n);
  return len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);
}

// integral over {w : w . normal < 0} of Y(w) Y(w)^T dw, by a Fibonacci sphere of 512 directions.
Mat below_surface_gram(const glm::dvec3& normal, int n) {
  constexpr int kDirections = 512;
  Mat m = Mat::Zero(n, n);
  for (int k = 0; k < kDirections; ++k) {
    const glm::dvec3 w = fibonacci_direction(k, kDirections);
    if (glm::dot(w, normal) >= 0.0) continue;
    const ShVector y = sh_basis(glm::vec3(w));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) m(i, j) += double(y[i]) * double(y[j]);
  }
  return m * (4.0 * kPi / kDirections);
}

// Refuses a system with NaN or Inf in its sums (the frame is not used).
Status check_system_finite(const LightSystem& system, int64_t frame_index) {
  for (double v : system.ata)
    if (!std::isfinite(v))
      return fail(ErrorKind::BadInput, "ssrt light estimation: frame " +
                                           std::to_string(frame_index) +
                                           ": T^T T holds NaN or Inf; frame not used");
  for (double v : system.atb)
    if (!std::isfinite(v))
      return fail(ErrorKind::BadInput, "ssrt light estimation: frame " +
                                           std::to_string(frame_index) +
                                           ": T^T I_c holds NaN or Inf; frame not used");
  return ok_status();
}

// The system's first n coefficients: T^T T into `ata` (symmetrised) and T^T I_c / albedo into
// `atb` (each row's luminance in all three channels for white light).
void load_system(const LightSystem& system, int n, const glm::dvec3& albedo, bool white_light, Mat& ata, Rhs& atb) {
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) ata(i, j) = system.ata[i * kMaxShCoeffs + j];
    for (int c = 0; c < 3; ++c) atb(i, c) = system.atb[i * 3 + c] / albedo[c];  // T l = I_c / a
  }
  if (white_light) {
    for (int i = 0; i < n; ++i) {
      const double y = luminance(glm::dvec3(atb(i, 0), atb(i, 1), atb(i, 2)));
      atb.row(i).setConstant(y);
    }
  }
  // Symmetrise (float sums from the GPU are not exactly symmetric).
  ata = (0.5 * (ata + ata.transpose())).eval();
}

// The eigenvalues of T^T T above `fraction` of the largest: directions of the SH space the data
// pins down on its own.
int constrained_directions(const Mat& ata, int n, double fraction) {
  Eigen::SelfAdjointEigenSolver<Mat> eig(ata, Eigen::EigenvaluesOnly);
  const auto& ev = eig.eigenvalues();
  const double max_ev = std::max(ev.maxCoeff(), 0.0);
  int constrained = 0;
  for (int i = 0; i < n; ++i)
    if (max_ev > 0.0 && ev(i) > fraction * max_ev) ++constrained;
  return constrained;
}

// The prior's band 0 fitted to this frame, its other bands as they are (ata(0, 0) > 0).
void refit_ambient(ShRgb& prior, const Mat& ata, const Rhs& atb, int n) {
  for (int c = 0; c < 3; ++c) {
    double rest = 0.0;
    for (int j = 1; j < n; ++j) rest += ata(0, j) * prior[j][c];
    prior[0][c] = std::max(0.0, (atb(0, c) - rest) / ata(0, 0));
  }
}

// Solves lhs x = rhs again with a penalty of `penalty` (times the sphere's Gram over the
// directions) on the radiance where x's luminance is negative, at most `rounds` times.
void solve_nonnegative(Rhs& x, const Mat& lhs, const Rhs& rhs, int n, double penalty, int rounds) {
  constexpr int kDirections = 256;
  Mat added = Mat::Zero(n, n);
  for (int round = 0; round < rounds; ++round) {
    Mat extra = Mat::Zero(n, n);
    int negative = 0;
    for (int k = 0; k < kDirections; ++k) {
      const glm::dvec3 w = fibonacci_direction(k, kDirections);
      const ShVector y = sh_basis(glm::vec3(w));
      double lum = 0.0;
      for (int i = 0; i < n; ++i)
        lum += double(y[size_t(i)]) * (0.2126 * x(i, 0) + 0.7152 * x(i, 1) + 0.0722 * x(i, 2));
      if (lum >= 0.0) continue;
      ++negative;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) extra(i, j) += double(y[size_t(i)]) * double(y[size_t(j)]);
    }
    if (negative == 0) break;
    added += extra * (penalty * 4.0 * kPi / kDirections);
    x = (lhs + added).ldlt().solve(rhs);
  }
}

}  // namespace

void LightSystem::add(const ShVector& transfer, const glm::dvec3& intensity) {
  for (int i = 0; i < kMaxShCoeffs; ++i) {
    const double ti = transfer[i];
    for (int j = 0; j < kMaxShCoeffs; ++j) ata[i * kMaxShCoeffs + j] += ti * double(transfer[j]);
    atb[i * 3 + 0] += ti * intensity.x;
    atb[i * 3 + 1] += ti * intensity.y;
    atb[i * 3 + 2] += ti * intensity.z;
  }
  samples += 1.0;
}

void LightSystem::add_view(const ShVector& basis, const glm::dvec3& intensity) {
  add(basis, intensity);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) view_ata1[size_t(i * 3 + j)] += double(basis[size_t(1 + i)]) * double(basis[size_t(1 + j)]);
    for (int c = 0; c < 3; ++c) view_atb1[size_t(i * 3 + c)] += double(basis[size_t(1 + i)]) * intensity[c];
  }
}

Expected<LightEstimator> LightEstimator::create(const LightEstimatorSettings& s) {
  MRGI_TRY(check_estimator_setting(s.bands >= 1 && s.bands <= kMaxShBands, "bands", "must be 1..4"));
  MRGI_TRY(check_estimator_setting(s.gray_albedo > 0.0 && s.gray_albedo <= 1.0, "gray_albedo",
                       "must be in (0, 1]"));
  MRGI_TRY(check_estimator_setting(s.relative_regularisation >= 0.0 && std::isfinite(s.relative_regularisation),
                       "relative_regularisation", "must be finite and >= 0"));
  MRGI_TRY(check_estimator_setting(s.min_regularisation > 0.0 && std::isfinite(s.min_regularisation),
                       "min_regularisation", "must be finite and > 0"));
  MRGI_TRY(check_estimator_setting(s.band_penalty >= 0.0 && std::isfinite(s.band_penalty), "band_penalty",
                       "must be finite and >= 0"));
  MRGI_TRY(check_estimator_setting(s.below_surface_penalty >= 0.0 && std::isfinite(s.below_surface_penalty),
                       "below_surface_penalty", "must be finite and >= 0"));
  MRGI_TRY(check_estimator_setting(s.lag_frames >= 0.0 && s.lag_frames <= 1e6, "lag_frames",
                       "must be 0..1e6 frames"));
  MRGI_TRY(check_estimator_setting(s.nonnegative_penalty >= 0.0 && std::isfinite(s.nonnegative_penalty),
                       "nonnegative_penalty", "must be finite and >= 0"));
  MRGI_TRY(check_estimator_setting(s.nonnegative_rounds >= 0 && s.nonnegative_rounds <= 16, "nonnegative_rounds",
                       "must be 0..16"));
  MRGI_TRY(check_estimator_setting(s.prior_radiance >= 0.0 && std::isfinite(s.prior_radiance),
                       "prior_radiance", "must be finite and >= 0"));
  MRGI_TRY(check_estimator_setting(s.confidence_eigen_fraction > 0.0 && s.confidence_eigen_fraction < 1.0,
                       "confidence_eigen_fraction", "must be in (0, 1)"));
  LightEstimator e(s);
  e.reset();
  return e;
}

void LightEstimator::set_albedo(const glm::dvec3& albedo) {
  for (int c = 0; c < 3; ++c)
    if (albedo[c] > 0.0 && albedo[c] <= 1.0) albedo_[c] = albedo[c];
}

void LightEstimator::reset() {
  filtered_ = ShRgb{};
  // Band 0 of a uniform radiance L is L * sqrt(4 pi) (Y00 = 1 / sqrt(4 pi)).
  filtered_[0] = glm::dvec3(settings_.prior_radiance * std::sqrt(4.0 * 3.14159265358979323846));
  frame_solution_ = filtered_;
  estimate_ = LightEstimate{};
  estimate_.bands = settings_.bands;
  fill_light_estimate(filtered_, settings_.bands, estimate_);
  have_previous_ = false;
  replace_updates_ = 0;
  last_frame_ = 0;
}

Expected<LightEstimate> LightEstimator::update(const LightSystem& system, int64_t frame_index,
                                               double timestamp_s, int solve_bands) {
  MRGI_TRY(check_system_finite(system, frame_index));
  if (solve_bands < 0 || solve_bands > settings_.bands)
    return fail(ErrorKind::BadUsage, "ssrt light estimation: solve_bands " +
                                         std::to_string(solve_bands) + " outside 0.." +
                                         std::to_string(settings_.bands));
  const int bands = solve_bands > 0 ? solve_bands : settings_.bands;
  const int n = bands * bands;
  Mat ata(n, n);
  Rhs atb(n, 3);
  load_system(system, n, albedo_, settings_.white_light, ata, atb);

  // Confidence: how many directions of the SH space the data pins down on its own.
  const int constrained = constrained_directions(ata, n, settings_.confidence_eigen_fraction);

  // Tikhonov towards the previous estimate (or the prior), with its band 0 re-fitted to this
  // frame first. Why: the system is rank-deficient whenever the view shows few normals, and the
  // regularised solution then moves from the prior only along the data's directions. For a floor
  // those mix band 0 with the band-1 "up" coefficient, so a floor darker than the prior predicts
  // was explained as light from below (without the re-fit the env_fisheye estimate pointed down,
  // 143 degrees off). Fitting the prior's ambient (band 0, always well constrained when any pixel
  // is valid) to the frame makes the prior explain the overall brightness; what is left for the
  // higher bands is what the data actually says about direction.
  ShRgb prior = filtered_;
  if (settings_.refit_prior_ambient && ata(0, 0) > 0.0) refit_ambient(prior, ata, atb, n);
  const double mean_diag = ata.trace() / n;
  const double lambda = settings_.relative_regularisation * std::max(mean_diag, 0.0) +
                        settings_.min_regularisation;
  Mat lhs = ata;
  Rhs rhs = atb;
  dominant_normal_ = n >= 4 ? dominant_surface_normal(ata, atb, system, albedo_, settings_.white_light) : glm::dvec3(0.0);
  const double mu = settings_.below_surface_penalty;
  if (mu > 0.0 && glm::length(dominant_normal_) > 0.5)
    lhs += (mu * std::max(mean_diag, 0.0)) * below_surface_gram(dominant_normal_, n);
  for (int i = 0; i < n; ++i) {
    const int l = sh_band(i);
    const double w = lambda * (1.0 + settings_.band_penalty * l * (l + 1));
    lhs(i, i) += w;
    for (int c = 0; c < 3; ++c) rhs(i, c) += w * prior[i][c];
  }
  // lhs is symmetric positive definite (T^T T is PSD, the added diagonal > 0): LDLT is exact
  // and stable; a robust fallback is not needed, but a non-finite result is still refused.
  Rhs x = lhs.ldlt().solve(rhs);
  // Radiance cannot be negative: where the solution's luminance is below 0 in some direction,
  // a penalty on the radiance there is added and the system solved again (an active set,
  // a few rounds). Least squares otherwise buys a better fit of the visible surfaces with
  // negative light from directions nothing constrains, which turns the dominant direction.
  const double nu = settings_.nonnegative_penalty;
  if (nu > 0.0 && n >= 4) solve_nonnegative(x, lhs, rhs, n, nu * std::max(mean_diag, 0.0), settings_.nonnegative_rounds);
  if (!x.allFinite()) {
    return fail(ErrorKind::Internal, "ssrt light estimation: frame " +
                                         std::to_string(frame_index) +
                                         ": the regularised solve gave NaN/Inf; frame not used");
  }
  for (int i = 0; i < kMaxShCoeffs; ++i)
    frame_solution_[i] = i < n ? glm::dvec3(x(i, 0), x(i, 1), x(i, 2)) : glm::dvec3(0.0);

  // Temporal filter. The first real frame replaces the prior outright.
  double alpha = 1.0;
  const bool replace = replace_updates_ > 0;
  if (replace) --replace_updates_;
  if (have_previous_ && !replace && settings_.lag_frames > 0.0) {
    // At least one frame (a frame solved twice, indices going back after a reset of the
    // source), at most ten time constants (a long gap: the old estimate is worthless).
    const double step = std::clamp(double(frame_index - last_frame_), 1.0, 10.0 * settings_.lag_frames);
    alpha = 1.0 - std::exp(-step / settings_.lag_frames);
  }
  const bool informative = constrained > 0;
  if (informative) {
    for (int i = 0; i < kMaxShCoeffs; ++i)
      filtered_[i] += alpha * (frame_solution_[i] - filtered_[i]);
    have_previous_ = true;
    last_frame_ = frame_index;
  }
  estimate_.valid = estimate_.valid || informative;
  estimate_.frame_index = frame_index;
  estimate_.timestamp = timestamp_s;
  estimate_.confidence = float(constrained) / float(n);
  fill_light_estimate(filtered_, settings_.bands, estimate_);
  return estimate_;
}

}  // namespace mrgi::light
