#include "light/radiance_samples.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mrgi::light {
namespace {

Status check_sample_setting(bool ok, const char* field, const std::string& rule) {
  if (ok) return ok_status();
  return fail(ErrorKind::BadUsage, std::string("RadianceSampleSettings.") + field + ": " + rule);
}

uint64_t mix64(uint64_t x) {  // splitmix64's finaliser: cells next to each other spread over the table
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// How an observation with clip mask `now` joins a kept one with mask `had` (bit c: channel c a
// lower bound): a measurement replaces bounds, a bound beside measurements is ignored (the
// measurements stand), otherwise it folds in and a channel either clipped stays a bound.
enum class Join { Fold, Replace, Ignore };
Join join(uint8_t had, uint8_t now) {
  if ((had != 0) == (now != 0)) return Join::Fold;
  return now ? Join::Ignore : Join::Replace;
}

}  // namespace

Expected<RadianceSamples> RadianceSamples::create(const RadianceSampleSettings& s) {
  MRGI_TRY(check_sample_setting(s.cell_m >= 0.005 && s.cell_m <= 1.0, "cell_m", "must be 0.005..1 metres"));
  MRGI_TRY(check_sample_setting(s.capacity >= 64 && s.capacity <= 65536, "capacity", "must be 64..65536 samples"));
  MRGI_TRY(check_sample_setting(s.colour_frames >= 1 && s.colour_frames <= 1024, "colour_frames", "must be 1..1024"));
  MRGI_TRY(check_sample_setting(s.change_ratio > 1.0 && std::isfinite(s.change_ratio), "change_ratio", "must be > 1"));
  MRGI_TRY(check_sample_setting(s.change_fraction > 0.0 && s.change_fraction <= 1.0, "change_fraction",
                                "must be in (0, 1]"));
  MRGI_TRY(check_sample_setting(s.change_min_samples >= 1, "change_min_samples", "must be >= 1"));
  MRGI_TRY(check_sample_setting(s.settle_observations >= 1 && s.settle_observations <= 1024, "settle_observations",
                                "must be 1..1024"));
  MRGI_TRY(check_sample_setting(s.distant_rows >= 1 && s.distant_rows <= 64, "distant_rows", "must be 1..64"));
  MRGI_TRY(check_sample_setting(s.distant_weight > 0.0 && std::isfinite(s.distant_weight), "distant_weight",
                                "must be > 0"));
  RadianceSamples r;
  r.settings_ = s;
  r.samples_.reserve(size_t(s.capacity));
  r.scratch_.reserve(size_t(s.capacity));
  size_t slots = 1;
  while (slots < size_t(s.capacity) * 2) slots <<= 1;
  r.table_.assign(slots, -1);
  r.table_mask_ = slots - 1;
  if (s.distant_views) r.distant_.assign(size_t(2 * s.distant_rows * s.distant_rows), DistantBin{});
  return r;
}

uint64_t RadianceSamples::key_of(const glm::dvec3& p, int bin) const {
  // 20 bits a coordinate (cells of 6 cm: +-31 km) and 6 for the orientation.
  constexpr int64_t kHalf = int64_t(1) << 19;
  auto q = [&](double v) {
    const int64_t c = std::clamp(int64_t(std::floor(v / settings_.cell_m)), -kHalf, kHalf - 1) + kHalf;
    return uint64_t(c);
  };
  return (q(p.x) << 46) | (q(p.y) << 26) | (q(p.z) << 6) | uint64_t(bin & 63);
}

int64_t RadianceSamples::find_slot(uint64_t key) const {
  uint64_t i = mix64(key) & table_mask_;
  for (;;) {  // the table is at most half full: an empty slot is always reached
    const int32_t at = table_[i];
    if (at < 0 || samples_[size_t(at)].key == key) return int64_t(i);
    i = (i + 1) & table_mask_;
  }
}

void RadianceSamples::rebuild_table() {
  std::fill(table_.begin(), table_.end(), -1);
  for (size_t k = 0; k < samples_.size(); ++k) table_[size_t(find_slot(samples_[k].key))] = int32_t(k);
}

void RadianceSamples::evict_oldest() {
  // Drop the quarter least recently seen (at least one sample).
  scratch_.clear();
  for (const Sample& s : samples_) scratch_.push_back(s.last_frame);
  const size_t cut = std::max<size_t>(1, samples_.size() / 4);
  std::nth_element(scratch_.begin(), scratch_.begin() + ptrdiff_t(cut - 1), scratch_.end());
  const int64_t oldest_kept = scratch_[cut - 1];
  size_t dropped = 0;
  samples_.erase(std::remove_if(samples_.begin(), samples_.end(),
                                [&](const Sample& s) {
                                  if (dropped < cut && s.last_frame <= oldest_kept) {
                                    ++dropped;
                                    return true;
                                  }
                                  return false;
                                }),
                 samples_.end());
  rebuild_table();
}

void RadianceSamples::begin(int64_t frame) {
  if (frame == frame_) return;
  frame_ = frame;
  reobserved_ = changed_ = 0;
}

void RadianceSamples::observe(const glm::dvec3& position, const glm::vec3& normal, int bin, const ShVector& transfer,
                              const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped) {
  begin(frame);
  if (!std::isfinite(position.x + position.y + position.z) || !std::isfinite(colour.x + colour.y + colour.z)) return;
  const uint64_t key = key_of(position, bin);
  int64_t slot = find_slot(key);
  if (table_[size_t(slot)] < 0) {
    if (samples_.size() >= size_t(settings_.capacity)) {
      evict_oldest();
      slot = find_slot(key);
    }
    table_[size_t(slot)] = int32_t(samples_.size());
    samples_.push_back({key, transfer, colour, colour, glm::vec3(position), normal, row_weight, clipped, 1, frame});
    return;
  }
  update(samples_[size_t(table_[size_t(slot)])], position, normal, &transfer, colour, row_weight, frame, clipped);
}

bool RadianceSamples::observe_if_settled(const glm::dvec3& position, const glm::vec3& normal, int bin,
                                         const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped) {
  begin(frame);
  if (!std::isfinite(position.x + position.y + position.z) || !std::isfinite(colour.x + colour.y + colour.z))
    return true;  // nothing to learn from it, and no transfer to compute for it
  const int64_t slot = find_slot(key_of(position, bin));
  if (table_[size_t(slot)] < 0) return false;
  Sample& s = samples_[size_t(table_[size_t(slot)])];
  if (s.observations < settings_.settle_observations || join(s.clipped, clipped) != Join::Fold) return false;
  update(s, position, normal, nullptr, colour, row_weight, frame, clipped);
  return true;
}

void RadianceSamples::update(Sample& s, const glm::dvec3& position, const glm::vec3& normal, const ShVector* transfer,
                             const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped) {
  switch (join(s.clipped, clipped)) {
    case Join::Ignore:
      s.last_frame = frame;
      return;
    case Join::Replace:
      s = Sample{s.key, transfer ? *transfer : s.transfer, colour, colour, glm::vec3(position), normal, row_weight, 0, 1, frame};
      return;
    case Join::Fold:
      s.clipped |= clipped;
      break;
  }
  if (s.last_frame < frame && !clipped) {
    // Seen in an earlier frame: does it show the light it showed then?
    const double before = luminance(s.colour), now = luminance(colour);
    ++reobserved_;
    const double r = settings_.change_ratio;
    if (before > 0.0 && now > 0.0 ? (now > before * r || now * r < before) : (before > 0.0) != (now > 0.0))
      ++changed_;
  }
  s.observations = std::min(s.observations + 1, settings_.colour_frames);
  const double a = 1.0 / double(s.observations);
  s.colour += a * (colour - s.colour);
  if (transfer)
    for (size_t i = 0; i < s.transfer.size(); ++i) s.transfer[i] += float(a) * ((*transfer)[i] - s.transfer[i]);
  s.position += float(a) * (glm::vec3(position) - s.position);
  s.normal += float(a) * (normal - s.normal);
  s.last_colour = colour;
  s.row_weight = row_weight;
  s.last_frame = frame;
}

bool RadianceSamples::end_frame(int64_t frame) {
  if (frame != frame_) return false;  // nothing observed in it
  const bool change = reobserved_ >= settings_.change_min_samples &&
                      double(changed_) >= settings_.change_fraction * double(reobserved_);
  reobserved_ = changed_ = 0;
  if (!change) return false;
  ++changes_;
  samples_.erase(std::remove_if(samples_.begin(), samples_.end(), [&](const Sample& s) { return s.last_frame < frame; }),
                 samples_.end());
  for (Sample& s : samples_) {
    s.colour = s.last_colour;
    s.observations = 1;
  }
  for (DistantBin& b : distant_) {
    if (b.observations == 0) continue;
    b.observations = b.last_frame < frame ? 0 : 1;
    b.colour = b.last_colour;
  }
  rebuild_table();
  return true;
}

void RadianceSamples::add_to(LightSystem& system, const ShRgb* estimate, const glm::dvec3& albedo,
                             const glm::dvec3* lamp_position, const glm::dvec3* lamp_intensity,
                             const std::function<glm::dvec3(const glm::vec3&, const glm::vec3&)>* taken_off,
                             const glm::dvec3* in_front_of) const {
  for (const Sample& s : samples_) {
    glm::dvec3 colour = s.colour;
    if (taken_off) colour = glm::max(colour - (*taken_off)(s.position, s.normal), glm::dvec3(0.0));
    if (lamp_position && lamp_intensity) {
      const glm::dvec3 v = *lamp_position - glm::dvec3(s.position);
      const double d = std::max(glm::length(v), 0.15);
      const double len = glm::length(glm::dvec3(s.normal));
      const double g = len > 0.0 ? std::max(0.0, glm::dot(glm::dvec3(s.normal) / len, v)) / (d * d * d) : 0.0;
      colour = glm::max(colour - (g / 3.14159265358979323846) * albedo * *lamp_intensity, glm::dvec3(0.0));
    }
    if (s.clipped) {
      if (!estimate) continue;
      glm::dvec3 predicted(0.0);
      for (int i = 0; i < kMaxShCoeffs; ++i) predicted += double(s.transfer[size_t(i)]) * (*estimate)[size_t(i)];
      for (int c = 0; c < 3; ++c)
        if (s.clipped & (1u << c)) colour[c] = std::max(colour[c], albedo[c] * predicted[c]);
    }
    const float w = std::sqrt(s.row_weight);
    ShVector t = s.transfer;
    for (float& v : t) v *= w;
    system.add(t, colour * double(w));
  }
  const double w = std::sqrt(settings_.distant_weight);
  for (const DistantBin& b : distant_) {
    if (b.observations == 0 || !in_front_of || glm::dot(glm::dvec3(b.direction), *in_front_of) <= 0.0) continue;
    glm::dvec3 colour = b.colour;
    if (b.clipped) {
      if (!estimate) continue;
      const glm::dvec3 predicted = sh_evaluate(*estimate, b.direction);
      for (int c = 0; c < 3; ++c)
        if (b.clipped & (1u << c)) colour[c] = std::max(colour[c], predicted[c]);
    }
    ShVector y = sh_basis(b.direction);
    for (float& v : y) v *= float(w);
    system.add_view(y, albedo * colour * w);
  }
}

void RadianceSamples::observe_distant(const glm::vec3& direction, const glm::dvec3& colour, int64_t frame,
                                      uint8_t clipped) {
  begin(frame);
  const float len = glm::length(direction);
  if (distant_.empty() || !(len > 0.0f) || !std::isfinite(len) || !std::isfinite(colour.x + colour.y + colour.z)) return;
  const glm::vec3 d = direction / len;
  // Equal-area bins: bands of equal height in d.y (Archimedes), equal azimuth steps in each.
  const int rows = settings_.distant_rows, cols = 2 * rows;
  const int row = std::clamp(int((d.y + 1.0f) * 0.5f * float(rows)), 0, rows - 1);
  const float azimuth = std::atan2(d.z, d.x);  // -pi..pi
  const int col = std::clamp(int((azimuth + float(kPi)) / float(2.0 * kPi) * float(cols)), 0, cols - 1);
  DistantBin& b = distant_[size_t(row * cols + col)];
  const Join j = b.observations == 0 ? Join::Replace : join(b.clipped, clipped);
  if (j == Join::Ignore) {
    b.last_frame = frame;
    return;
  }
  if (j == Join::Replace) {
    b = DistantBin{d, colour, colour, clipped, 1, frame};
    return;
  }
  b.clipped |= clipped;
  b.observations = std::min(b.observations + 1, settings_.colour_frames);
  const double a = 1.0 / double(b.observations);
  b.colour += a * (colour - b.colour);
  b.direction += float(a) * (d - b.direction);
  b.last_colour = colour;
  b.last_frame = frame;
}

void RadianceSamples::clear() {
  samples_.clear();
  std::fill(table_.begin(), table_.end(), -1);
  std::fill(distant_.begin(), distant_.end(), DistantBin{});
  reobserved_ = changed_ = 0;
  frame_ = -1;
}

}  // namespace mrgi::light
