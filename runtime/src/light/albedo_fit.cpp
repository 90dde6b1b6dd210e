#include "light/albedo_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "light/sh_tools.h"

namespace mrgi::light {
namespace {

constexpr int kMaxColumns = kMaxShCoeffs + 2;  // SH, bounce, near lamp
const glm::dvec3 kLuminance(0.2126, 0.7152, 0.0722);
constexpr double kMinInformation = 1e-3;  // the bounce column's share not explained by the others, below: no fit
constexpr double kLayer = 1.5;  // a bin's nearest layer: within this factor of its nearest sample (+ 2 cells)
constexpr int kMaxSplit = 6;    // an emitter near a point is split into at most this squared pieces
constexpr size_t kSplitPieces = 16384;  // the pieces' scratch beyond one per emitter, reserved at start-up

// Two unit tangents of a unit normal (Duff et al. 2017, "Building an orthonormal basis, revisited").
void tangents(const glm::vec3& n, glm::vec3& t1, glm::vec3& t2) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
  t1 = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t2 = glm::vec3(b, sign + n.y * n.y * a, -n.y);
}

glm::dvec3 unit_normal(const glm::vec3& n) {
  const double len = glm::length(glm::dvec3(n));
  return len > 0.5 ? glm::dvec3(n) / len : glm::dvec3(0.0);
}

// Direction bins: a cube map of kFace x kFace texels per face, each with its centre direction,
// solid angle (integrated on a 8 x 8 sub-grid) and SH basis.
int cube_bin(const glm::dvec3& w) {
  const glm::dvec3 a = glm::abs(w);
  int face;
  double u, v, m;
  if (a.x >= a.y && a.x >= a.z) { face = w.x > 0 ? 0 : 1; m = a.x; u = w.y; v = w.z; }
  else if (a.y >= a.z) { face = w.y > 0 ? 2 : 3; m = a.y; u = w.x; v = w.z; }
  else { face = w.z > 0 ? 4 : 5; m = a.z; u = w.x; v = w.y; }
  const int i = std::clamp(int((u / m + 1.0) * 0.5 * AlbedoFitter::kFace), 0, AlbedoFitter::kFace - 1);
  const int j = std::clamp(int((v / m + 1.0) * 0.5 * AlbedoFitter::kFace), 0, AlbedoFitter::kFace - 1);
  return (face * AlbedoFitter::kFace + j) * AlbedoFitter::kFace + i;
}

}  // namespace

ShRgb light_at_point(const ShRgb& sources, const ShRgb& distant, const ShRgb& near, const ShMatrix& hidden) {
  ShRgb out{};
  for (int i = 0; i < kMaxShCoeffs; ++i) {
    out[size_t(i)] = sources[size_t(i)] + near[size_t(i)];
    for (int j = 0; j < kMaxShCoeffs; ++j) out[size_t(i)] -= hidden[size_t(i * kMaxShCoeffs + j)] * distant[size_t(j)];
  }
  return out;
}

AlbedoFitter::AlbedoFitter(const AlbedoFitSettings& s) : settings_(s) {
  receivers_.reserve(size_t(std::max(16, s.receivers)));
  fitted_.reserve(receivers_.capacity());
  emitters_.reserve(size_t(std::max(64, s.emitters)));
  near_emitters_.reserve(size_t(std::clamp(s.near_field_emitters, 64, 65536)));  // read to its capacity
  pieces_.reserve(std::max(emitters_.capacity(), near_emitters_.capacity()) + kSplitPieces);
  bins_.resize(size_t(kBins));
  coverage_.resize(size_t(kBins));
  nearest_.resize(size_t(kBins));
  radiance_.resize(size_t(kBins));
  constexpr int kSub = 8;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < kFace; ++j)
      for (int i = 0; i < kFace; ++i) {
        Bin& b = bins_[size_t((face * kFace + j) * kFace + i)];
        b.solid_angle = 0.0;
        for (int sj = 0; sj < kSub; ++sj)
          for (int si = 0; si < kSub; ++si) {
            const double u = -1.0 + 2.0 * (i + (si + 0.5) / kSub) / kFace, v = -1.0 + 2.0 * (j + (sj + 0.5) / kSub) / kFace;
            const double du = 2.0 / (kFace * kSub);
            b.solid_angle += du * du / std::pow(1.0 + u * u + v * v, 1.5);
          }
        const double u = -1.0 + 2.0 * (i + 0.5) / kFace, v = -1.0 + 2.0 * (j + 0.5) / kFace;
        const double sign = face % 2 == 0 ? 1.0 : -1.0;
        glm::dvec3 w = face < 2 ? glm::dvec3(sign, u, v) : face < 4 ? glm::dvec3(u, sign, v) : glm::dvec3(u, v, sign);
        b.direction = glm::normalize(w);
        b.sh = sh_basis(glm::vec3(b.direction));
        min_bin_solid_angle_ = std::min(min_bin_solid_angle_, b.solid_angle);
      }
}

void AlbedoFitter::cover_bins(const glm::vec3& p, const glm::vec3* hemisphere, const std::vector<Emitter>& emitters,
                              bool split) {
  // What each direction bin around the point sees: the nearest layer of emitters in it (those
  // within kLayer of the nearest: a table top hides the wall behind it), by the solid angle they
  // cover (at most the bin's) and their mean radiance; an emitter seen from behind (a table top
  // from the floor under it) covers its share dark, its lit side facing away. The rest of the
  // bin is the distant light. With `split`, an emitter whose square would span more than half
  // the smallest bin is split into pieces first (a 6 cm cell 10 cm below the objects spans ten
  // bins: whole, it covered one). The receivers' strided emitters are not split: each stands for
  // samples elsewhere, and split squares that overlap covered the corner's bins twice (its
  // albedo read 0.21 for 0.3).
  std::fill(coverage_.begin(), coverage_.end(), 0.0);
  std::fill(radiance_.begin(), radiance_.end(), glm::dvec3(0.0));
  std::fill(nearest_.begin(), nearest_.end(), std::numeric_limits<double>::infinity());
  pieces_.clear();
  const double piece_omega = 0.5 * min_bin_solid_angle_;
  auto add_piece = [&](const glm::vec3& v, float area, int emitter) {
    const float d2 = glm::dot(v, v);
    if (d2 < float(min_d2_) || (hemisphere && glm::dot(*hemisphere, v) <= 0.0f)) return;
    const float d = std::sqrt(d2);
    const int b = cube_bin(glm::dvec3(v / d));
    nearest_[size_t(b)] = std::min(nearest_[size_t(b)], double(d));
    pieces_.push_back({v, d, area, b, emitter});
  };
  for (size_t i = 0; i < emitters.size(); ++i) {
    const Emitter& e = emitters[i];
    const glm::vec3 v = e.p - p;
    const double d2 = std::max(double(glm::dot(v, v)), min_d2_);
    const int m = split ? std::clamp(int(std::ceil(std::sqrt(double(e.area) / d2 / piece_omega))), 1, kMaxSplit) : 1;
    // Room is kept for one piece of every emitter still to come, so the scratch never grows.
    if (m == 1 || pieces_.size() + size_t(m * m) + (emitters.size() - i - 1) > pieces_.capacity()) {
      add_piece(v, e.area, int(i));
      continue;
    }
    glm::vec3 t1, t2;
    tangents(e.n, t1, t2);
    const float side = std::sqrt(e.area), a = e.area / float(m * m);
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x) {
        const float u = ((float(x) + 0.5f) / float(m) - 0.5f) * side, w = ((float(y) + 0.5f) / float(m) - 0.5f) * side;
        add_piece(v + u * t1 + w * t2, a, int(i));
      }
  }
  for (const Piece& q : pieces_) {
    if (double(q.d) > kLayer * nearest_[size_t(q.bin)] + layer_m_) continue;
    const Emitter& e = emitters[size_t(q.emitter)];
    const float cos_e_d = -glm::dot(e.n, q.v);  // cos_e d; < 0 seen from behind
    const double omega = double(q.area * std::abs(cos_e_d) / (q.d * q.d * q.d));
    coverage_[size_t(q.bin)] += omega;
    if (cos_e_d > 0.0f) radiance_[size_t(q.bin)] += omega * glm::dvec3(e.c);
  }
}

void AlbedoFitter::receiver_terms(Receiver& r) {
  const glm::vec3 n(r.n);
  cover_bins(glm::vec3(r.p), &n, emitters_, false);
  r.t.fill(0.0f);
  r.bounce = glm::dvec3(0.0);
  for (int b = 0; b < kBins; ++b) {
    const Bin& bin = bins_[size_t(b)];
    const double cos_r = glm::dot(r.n, bin.direction);
    if (cos_r <= 0.0) continue;
    const double covered = coverage_[size_t(b)];
    const double f = std::min(1.0, covered / bin.solid_angle);
    const double w = cos_r * bin.solid_angle / kPi;
    if (covered > 0.0) r.bounce += (f * w / covered) * radiance_[size_t(b)];
    for (int i = 0; i < kMaxShCoeffs; ++i) r.t[size_t(i)] += float((1.0 - f) * w) * bin.sh[size_t(i)];
  }
}

bool AlbedoFitter::near_field_at(const glm::dvec3& focus, const RadianceSamples& store, ShRgb& out, ShMatrix* hidden) {
  out = ShRgb{};
  if (hidden) hidden->fill(0.0);
  const auto& all = store.samples();
  if (emitters_.empty() || all.empty()) return false;
  // Split only where each emitter is its own cell (the stage reserves room for the whole store):
  // a strided one stands for samples elsewhere too.
  const size_t stride = read_emitters(store, near_emitters_.capacity(), near_emitters_);
  cover_bins(glm::vec3(focus), nullptr, near_emitters_, stride == 1);
  for (int b = 0; b < kBins; ++b) {
    const double covered = coverage_[size_t(b)];
    if (!(covered > 0.0)) continue;
    const Bin& bin = bins_[size_t(b)];
    const double f = std::min(1.0, covered / bin.solid_angle);
    const glm::dvec3 l = radiance_[size_t(b)] / covered;  // the covering samples' mean radiance
    for (int i = 0; i < kMaxShCoeffs; ++i) out[size_t(i)] += (f * bin.solid_angle * double(bin.sh[size_t(i)])) * l;
    if (hidden)
      for (int i = 0; i < kMaxShCoeffs; ++i)
        for (int j = 0; j < kMaxShCoeffs; ++j)
          (*hidden)[size_t(i * kMaxShCoeffs + j)] += f * bin.solid_angle * double(bin.sh[size_t(i)]) * double(bin.sh[size_t(j)]);
  }
  return true;
}

size_t AlbedoFitter::read_emitters(const RadianceSamples& store, size_t cap, std::vector<Emitter>& out) const {
  // Every sample, strided to at most `cap` (what `out` was reserved for), each standing for the
  // area of the samples it stands for.
  const auto& all = store.samples();
  const size_t stride = std::max<size_t>(1, (all.size() + cap - 1) / cap);
  const double cell = store.settings().cell_m;
  const float area = float(cell * cell * double(stride));
  out.clear();
  for (size_t i = 0; i < all.size(); i += stride) {
    const glm::dvec3 n = unit_normal(all[i].normal);
    if (n == glm::dvec3(0.0)) continue;
    out.push_back({all[i].position, glm::vec3(n), glm::vec3(all[i].colour), area});
  }
  return stride;
}

bool AlbedoFitter::begin(const RadianceSamples& store) {
  receivers_.clear();
  emitters_.clear();
  next_ = 0;
  const auto& all = store.samples();
  size_t unclipped = 0;
  for (const auto& s : all) unclipped += s.clipped ? 0 : 1;
  if (!settings_.enabled || int(unclipped) < settings_.min_samples) return false;
  const double cell = store.settings().cell_m;
  min_d2_ = cell * cell;
  layer_m_ = 2.0 * cell;
  // Receivers: unclipped samples, strided. Emitters: every sample, strided (read_emitters).
  const size_t cap = size_t(std::max(16, settings_.receivers));
  const size_t stride = std::max<size_t>(1, (unclipped + cap - 1) / cap);
  size_t k = 0;
  for (const auto& s : all) {
    if (s.clipped || (k++ % stride) != 0) continue;
    const glm::dvec3 n = unit_normal(s.normal);
    if (n != glm::dvec3(0.0)) receivers_.push_back({glm::dvec3(s.position), n, s.colour, glm::dvec3(0.0), double(s.row_weight), ShVector{}});
  }
  read_emitters(store, size_t(std::max(64, settings_.emitters)), emitters_);
  if (receivers_.size() < 16) {
    receivers_.clear();
    return false;
  }
  return true;
}

bool AlbedoFitter::step(int count) {
  const size_t end = std::min(receivers_.size(), next_ + size_t(std::max(1, count > 0 ? count : settings_.receivers_per_step)));
  for (; next_ < end; ++next_) receiver_terms(receivers_[next_]);
  return !busy();
}

AlbedoFit AlbedoFitter::fit(const RadianceSamples& store, const PointLampFit* lamp) {
  if (!begin(store)) {
    AlbedoFit out;
    out.albedo = glm::dvec3(settings_.prior);
    return out;
  }
  while (!step()) {
  }
  return solve(lamp);
}

AlbedoFit AlbedoFitter::solve(const PointLampFit* lamp) {
  AlbedoFit out;
  out.albedo = glm::dvec3(settings_.prior);
  out.receivers = int(next_);
  if (busy() || receivers_.size() < 16) return out;
  // The receivers' bounce is known whether or not it tells the albedo.
  fitted_.assign(receivers_.begin(), receivers_.end());
  // Per channel, or once on luminance for all three (the grey albedo: a coloured wall's colour
  // stays with the light, as the estimator's grey world has it, only the brightness is measured).
  double explained = 0.0, observed = 0.0;
  for (int ch = 0; ch < (settings_.per_channel ? 3 : 1); ++ch) {
    const glm::dvec3 pick = settings_.per_channel ? glm::dvec3(ch == 0, ch == 1, ch == 2) : kLuminance;
    double a = 0.0, sigma = 0.0;
    if (!solve_pick(pick, lamp, a, sigma)) return out;
    const double wp = 1.0 / (settings_.prior_sigma * settings_.prior_sigma), wd = 1.0 / (sigma * sigma);
    const double posterior = std::clamp((a * wd + settings_.prior * wp) / (wd + wp), settings_.min_albedo, settings_.max_albedo);
    for (int c = 0; c < 3; ++c) {
      if (settings_.per_channel && c != ch) continue;
      out.data_albedo[c] = a;
      out.data_sigma[c] = sigma;
      out.albedo[c] = posterior;
    }
    for (const Receiver& r : receivers_) {
      explained += glm::dot(pick * kLuminance, posterior * r.bounce) / glm::dot(pick, kLuminance);
      observed += glm::dot(pick * kLuminance, r.c) / glm::dot(pick, kLuminance);
    }
  }
  out.bounce_share = observed > 0.0 ? explained / observed : 0.0;
  out.found = true;
  return out;
}

bool AlbedoFitter::solve_pick(const glm::dvec3& pick, const PointLampFit* lamp, double& albedo, double& sigma) const {
  const bool with_lamp = lamp && lamp->found;
  const int bands = std::clamp(settings_.bands, 1, kMaxShBands);
  const int n_sh = bands * bands, cols = n_sh + 1 + (with_lamp ? 1 : 0);
  const int ia = n_sh;  // the bounce column: its coefficient is the albedo
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxColumns>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxColumns, 1>;
  Mat ata = Mat::Zero(cols, cols);
  Vec aty = Vec::Zero(cols);
  double yy = 0.0;
  Vec f(cols);
  for (const Receiver& r : receivers_) {
    for (int i = 0; i < n_sh; ++i) f(i) = double(r.t[size_t(i)]);
    f(ia) = glm::dot(pick, r.bounce);
    if (with_lamp) {
      const glm::dvec3 v = lamp->position - r.p;
      const double d = std::max(glm::length(v), kMinLampDistance);
      f(ia + 1) = std::max(0.0, glm::dot(r.n, v)) / (d * d * d);
    }
    const double y = glm::dot(pick, r.c);
    ata.noalias() += r.weight * f * f.transpose();
    aty += (r.weight * y) * f;
    yy += r.weight * y * y;
  }
  // What the bounce column holds beyond the other columns (its Schur complement): without it,
  // nothing is known of the albedo (a floor alone bounces nothing onto itself).
  const double column = ata(ia, ia);
  ata.diagonal().array() += 1e-6 * ata.trace() / double(cols);
  const Eigen::LDLT<Mat> ldlt(ata);
  const Vec beta = ldlt.solve(aty);
  if (!beta.allFinite() || !(column > 0.0)) return false;
  Vec unit = Vec::Zero(cols);
  unit(ia) = 1.0;
  const double inverse_aa = ldlt.solve(unit)(ia);  // 1 / Schur complement
  if (!(inverse_aa > 0.0) || !(1.0 / inverse_aa > kMinInformation * column)) return false;
  // Weighted least squares: the residual's variance per unit weight times (A^T W A)^-1.
  const double sigma2 = std::max(0.0, yy - beta.dot(aty)) / std::max(1.0, double(receivers_.size()) - double(cols));
  albedo = beta(ia);
  sigma = std::sqrt(std::max(1e-12, sigma2 * inverse_aa));
  return std::isfinite(albedo) && std::isfinite(sigma);
}

}  // namespace mrgi::light
