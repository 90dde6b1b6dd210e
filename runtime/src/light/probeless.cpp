#include "light/probeless.h"

#include "light/camera_color.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/frame_constants.glsl"
#include "image/srgb.h"
#include "shared/mrgi_shared.h"
#include "shared/transfer_math.h"

namespace mrgi::light {
namespace {

Status check_probeless_setting(bool ok, const char* field, const std::string& rule) {
  if (ok) return ok_status();
  return fail(ErrorKind::BadUsage, std::string("ProbelessSettings.") + field + ": " + rule);
}

constexpr int kSaturated = 250;            // 8-bit colour at or above: clipped, not a measurement
constexpr float kSameSurface = float(MRGI_DEPTH_EDGE_RELATIVE);

}  // namespace

glm::dvec3 lamp_irradiance(const LightDesc& l, const glm::dvec3& p, glm::dvec3& to_light) {
  const glm::dvec3 rgb = glm::dvec3(l.color) * double(l.intensity);
  if (l.type == LightType::Directional) {
    to_light = -glm::normalize(glm::dvec3(l.direction));
    return rgb;
  }
  const glm::dvec3 d = glm::dvec3(l.position) - p;
  const double d2 = std::max(glm::dot(d, d), 1e-6);
  to_light = d / std::sqrt(d2);
  double cone = 1.0;
  if (l.type == LightType::Spot)
    cone = shader::spot_falloff(float(glm::dot(glm::normalize(glm::dvec3(l.direction)), -to_light)),
                                std::cos(glm::radians(l.outer_angle_deg)),
                                std::cos(glm::radians(l.inner_angle_deg)));
  return rgb * (cone / d2);
}

void ProbelessBuilder::set_known_lamps(const std::vector<LightDesc>& lamps, double albedo) {
  known_lamps_ = lamps;
  known_albedo_ = albedo;
}

Expected<ProbelessBuilder> ProbelessBuilder::create(const ProbelessSettings& s, const Intrinsics& color,
                                                    const Intrinsics& depth, double depth_scale) {
  MRGI_TRY(check_probeless_setting(s.grid_width >= 16 && s.grid_width <= 512, "grid_width", "must be 16..512 samples"));
  MRGI_TRY(check_probeless_setting(s.directions >= 16 && s.directions <= 1024, "directions", "must be 16..1024"));
  MRGI_TRY(check_probeless_setting(s.march_steps >= 1 && s.march_steps <= 64, "march_steps", "must be 1..64"));
  MRGI_TRY(check_probeless_setting(s.radius_m > 0.0 && std::isfinite(s.radius_m), "radius_m", "must be > 0 metres"));
  MRGI_TRY(check_probeless_setting(s.parts >= 1 && s.parts <= 16, "parts", "must be 1..16 frames"));
  MRGI_TRY(check_probeless_setting(s.distant_margin >= 0 && s.distant_margin <= 8, "distant_margin", "must be 0..8 blocks"));
  const int stride = std::max(2, depth.width / s.grid_width);
  if (color.width < 1 || color.height < 1 || depth.width < stride || depth.height < stride ||
      !(color.fx > 0) || !(color.fy > 0) || !(depth.fx > 0) || !(depth.fy > 0) || !(depth_scale > 0))
    return fail(ErrorKind::BadInput, "probeless light estimation: camera intrinsics need sizes of at "
                                     "least one sample block, focal lengths and depth_scale > 0");
  ProbelessBuilder b;
  b.settings_ = s;
  b.color_ = color;
  b.depth_ = depth;
  b.depth_scale_ = depth_scale;
  b.stride_ = stride;
  b.chroma_hist_.assign(size_t(kChromaBins) * size_t(kChromaBins), 0);
  b.samples_.reserve(size_t(depth.width / stride) * size_t(depth.height / stride / s.parts + 1));
  b.grid_w_ = depth.width / stride;
  b.grid_h_ = depth.height / stride;
  const size_t cells = size_t(b.grid_w_) * size_t(b.grid_h_);
  b.position_.assign(cells, glm::vec3(0.0f));
  b.normal_.assign(cells, glm::vec3(0.0f));
  b.bin_.assign(cells, -1);
  b.balance_.assign(cells, 0.0f);
  b.bin_count_.assign(kNormalBins, 0);
  for (int k = 0; k < kNormalBins; ++k) b.bin_direction_.push_back(glm::vec3(fibonacci_direction(k, kNormalBins)));
  b.directions_.reserve(size_t(s.directions));
  b.direction_sh_.reserve(size_t(s.directions));
  for (int k = 0; k < s.directions; ++k) {
    const glm::vec3 w(fibonacci_direction(k, s.directions));
    b.directions_.push_back(w);
    b.direction_sh_.push_back(sh_basis(w));
  }
  // Neighbouring directions of a Fibonacci sphere are about sqrt(4 pi / N) apart: the median
  // angle eq. 9 takes from a Delaunay triangulation, without building one.
  b.chi_ = shader::ssrt_chi_from_median_angle(float(std::sqrt(4.0 * kPi / s.directions)));
  return b;
}

void ProbelessBuilder::build_positions(const frame::DepthView& depth) {
  const int s = stride_;
  const glm::vec4 k(float(depth_.fx), float(depth_.fy), float(depth_.cx), float(depth_.cy));
  const float to_m = float(1.0 / depth_scale_);
  // At most 4 x 4 depths a block: enough to average the noise out, and every frame rebuilds the
  // whole grid (the visibility search reads any cell), so this is most of a frame's cost.
  const int step = std::max(1, s / 4);
  for (int gy = 0; gy < grid_h_; ++gy) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      // The block's centre depth picks the surface; the block's depths on that surface are
      // averaged (Kinect noise grows with distance squared; 16 samples take most of it out).
      const int x0 = gx * s, y0 = gy * s;
      const uint16_t centre = depth.at(x0 + s / 2, y0 + s / 2);
      glm::vec3& out = position_[size_t(gy) * grid_w_ + gx];
      out = glm::vec3(0.0f);
      if (centre == 0) continue;
      const float zc = float(centre) * to_m;
      double sum_z = 0.0, sum_u = 0.0, sum_v = 0.0;
      int count = 0;
      for (int y = y0; y < y0 + s; y += step) {
        const uint16_t* row = depth.row(y);
        for (int x = x0; x < x0 + s; x += step) {
          const float z = float(row[x]) * to_m;
          if (row[x] == 0 || std::abs(z - zc) > kSameSurface * zc) continue;
          sum_z += z;
          sum_u += x;
          sum_v += y;
          ++count;
        }
      }
      const float z = float(sum_z / count);
      out = shader::unproject_pinhole(glm::vec2(float(sum_u / count), float(sum_v / count)), z, k);
    }
  }
}

void ProbelessBuilder::build_normals(const glm::mat3& rot) {
  auto cell = [&](int gx, int gy) -> const glm::vec3& { return position_[size_t(gy) * grid_w_ + gx]; };
  auto same_surface = [](const glm::vec3& a, const glm::vec3& b) {
    return a.z > 0.0f && b.z > 0.0f && std::abs(a.z - b.z) <= kSameSurface * std::min(a.z, b.z);
  };
  std::fill(bin_count_.begin(), bin_count_.end(), 0);
  for (int gy = 0; gy < grid_h_; ++gy) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      glm::vec3& out = normal_[size_t(gy) * grid_w_ + gx];
      out = glm::vec3(0.0f);
      bin_[size_t(gy) * grid_w_ + gx] = -1;
      const glm::vec3 p = cell(gx, gy);
      if (!(p.z > 0.0f)) continue;
      // Normal from the neighbouring cells on the same surface (central where both sides are,
      // else one-sided), facing the camera.
      glm::vec3 dx(0.0f), dy(0.0f);
      const glm::vec3 l = gx > 0 ? cell(gx - 1, gy) : glm::vec3(0.0f);
      const glm::vec3 r = gx + 1 < grid_w_ ? cell(gx + 1, gy) : glm::vec3(0.0f);
      const glm::vec3 u = gy > 0 ? cell(gx, gy - 1) : glm::vec3(0.0f);
      const glm::vec3 d = gy + 1 < grid_h_ ? cell(gx, gy + 1) : glm::vec3(0.0f);
      const bool hl = same_surface(p, l), hr = same_surface(p, r), hu = same_surface(p, u), hd = same_surface(p, d);
      if (hl && hr) dx = r - l; else if (hr) dx = r - p; else if (hl) dx = p - l;
      if (hu && hd) dy = d - u; else if (hd) dy = d - p; else if (hu) dy = p - u;
      glm::vec3 n_cam = glm::cross(dy, dx);
      const float len = glm::length(n_cam);
      if (!(len > 1e-12f)) continue;
      n_cam /= len;
      if (glm::dot(n_cam, p) > 0.0f) n_cam = -n_cam;
      out = n_cam;
      // The orientation's bin (the nearest of kNormalBins directions, world space).
      const glm::vec3 nw = rot * n_cam;
      int best = 0;
      float best_dot = -2.0f;
      for (int b = 0; b < kNormalBins; ++b)
        if (const float d = glm::dot(nw, bin_direction_[size_t(b)]); d > best_dot) {
          best_dot = d;
          best = b;
        }
      bin_[size_t(gy) * grid_w_ + gx] = best;
      ++bin_count_[size_t(best)];
    }
  }
  int used = 0, total = 0;
  for (int c : bin_count_) {
    used += c > 0 ? 1 : 0;
    total += c;
  }
  for (size_t i = 0; i < balance_.size(); ++i) {
    const int b = bin_[i];
    balance_[i] = b < 0 ? 0.0f
                  : settings_.balance_normals ? float(total) / float(used * bin_count_[size_t(b)])
                                              : 1.0f;
  }
}

bool ProbelessBuilder::block_colour(const CameraColor& camera, double exposure, const glm::vec2& c,
                                    bool stop_at_saturated, glm::dvec3& colour, uint8_t& saturated) const {
  const auto& lut = srgb8_to_linear_table();
  const int half = std::max(1, int(std::lround(0.5 * stride_ * color_.fx / depth_.fx)));
  const int cx0 = std::max(0, int(c.x) - half), cx1 = std::min(color_.width, int(c.x) + half);
  const int cy0 = std::max(0, int(c.y) - half), cy1 = std::min(color_.height, int(c.y) + half);
  colour = glm::dvec3(0.0);
  saturated = 0;
  int count = 0;
  for (int y = cy0; y < cy1; ++y) {
    for (int x = cx0; x < cx1; ++x) {
      const std::array<uint8_t, 3> px = camera.at(x, y);
      for (int ch = 0; ch < 3; ++ch)
        if (px[size_t(ch)] >= kSaturated) saturated |= uint8_t(1u << ch);
      if (saturated && stop_at_saturated) return false;
      colour += glm::dvec3(lut[px[0]], lut[px[1]], lut[px[2]]);
      ++count;
    }
  }
  if (count == 0) return false;
  colour /= double(count) * exposure;
  return true;
}

void ProbelessBuilder::add_distant_views(int part, const glm::mat3& rot, const CameraColor& camera, double exposure,
                                         int64_t frame, RadianceSamples& samples) const {
  const int m = settings_.distant_margin, s = stride_;
  const glm::vec4 kd(float(depth_.fx), float(depth_.fy), float(depth_.cx), float(depth_.cy));
  const glm::vec4 kc(float(color_.fx), float(color_.fy), float(color_.cx), float(color_.cy));
  auto has_depth = [&](int gx, int gy) { return position_[size_t(gy) * grid_w_ + gx].z > 0.0f; };
  for (int gy = part; gy < grid_h_; gy += settings_.parts) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      bool near = false;
      for (int y = std::max(0, gy - m); y <= std::min(grid_h_ - 1, gy + m) && !near; ++y)
        for (int x = std::max(0, gx - m); x <= std::min(grid_w_ - 1, gx + m) && !near; ++x) near = has_depth(x, y);
      if (near) continue;
      // The depth camera's ray through the block's centre pixel (the cameras share a centre).
      const glm::vec3 ray = shader::unproject_pinhole(glm::vec2(float(gx * s + s / 2), float(gy * s + s / 2)), 1.0f, kd);
      glm::dvec3 colour;
      uint8_t saturated = 0;
      if (!block_colour(camera, exposure, shader::project_pinhole(ray, kc), false, colour, saturated)) continue;
      samples.observe_distant(rot * ray, colour, frame, saturated);
    }
  }
}

Status ProbelessBuilder::add_part(const frame::CameraView& view, double exposure, int part, LightSystem& system,
                                  RadianceSamples* samples) {
  const CameraColor camera(view);
  const glm::dmat4& camera_to_world = view.camera_to_world;
  if (view.depth.empty() || view.depth.width != depth_.width || view.depth.height != depth_.height ||
      camera.width() != color_.width || camera.height() != color_.height)
    return fail(ErrorKind::BadInput, "probeless light estimation: frame " + std::to_string(view.index) +
                                         " does not have the cameras' sizes");
  if (part < 0 || part >= settings_.parts)
    return fail(ErrorKind::BadUsage, "probeless light estimation: part " + std::to_string(part) +
                                         " outside 0.." + std::to_string(settings_.parts - 1));
  if (!(exposure > 0.0)) exposure = 1.0;
  build_positions(view.depth);
  const glm::mat3 rot = glm::mat3(camera_to_world);
  build_normals(rot);
  const glm::mat3 rot_t = glm::transpose(rot);
  const glm::vec4 kd(float(depth_.fx), float(depth_.fy), float(depth_.cx), float(depth_.cy));
  const glm::vec4 kc(float(color_.fx), float(color_.fy), float(color_.cx), float(color_.cy));
  const int s = stride_;
  const float radius = float(settings_.radius_m);
  const float solid_angle = float(4.0 * kPi / settings_.directions);
  const float inv_stride = 1.0f / float(s);
  auto cell = [&](int gx, int gy) -> const glm::vec3& { return position_[size_t(gy) * grid_w_ + gx]; };
  // Visibility from camera-space point p along camera-space direction w_cam over `reach` metres:
  // the direction is marched through the depth grid, and a grid surface in front of a step
  // (within twice the radius: a range check, as the ssrt transfer) occludes it by eq. 7-8's
  // continuous K; leaving the view ends the search (unknown counts as visible).
  auto visibility = [&](const glm::vec3& p, const glm::vec3& w_cam, float reach) {
    float k = 1.0f;
    for (int step = 1; step <= settings_.march_steps && k > 0.0f; ++step) {
      const glm::vec3 q = p + w_cam * (reach * float(step) / float(settings_.march_steps));
      if (!(q.z > 0.0f)) break;
      const glm::vec2 px = shader::project_pinhole(q, kd) * inv_stride;
      const int qx = int(std::floor(px.x)), qy = int(std::floor(px.y));
      if (qx < 0 || qy < 0 || qx >= grid_w_ || qy >= grid_h_) break;
      const glm::vec3& sp = cell(qx, qy);
      if (!(sp.z > 0.0f) || sp.z >= q.z - 0.02f * q.z || q.z - sp.z > 2.0f * radius) continue;
      k = std::min(k, shader::ssrt_visibility_k(p, sp, w_cam, chi_));
    }
    return k;
  };
  // First the part's samples and their colours, so the light's colour can be voted on before
  // any row is added.
  samples_.clear();
  for (int gy = part; gy < grid_h_; gy += settings_.parts) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      const glm::vec3 p = cell(gx, gy);
      if (!(p.z > 0.0f) || normal_[size_t(gy) * grid_w_ + gx] == glm::vec3(0.0f)) continue;
      // Colour: the linear mean of the block's pixels where the depth camera's sample lands in
      // the colour camera (same centre; intrinsics may differ).
      glm::dvec3 colour;
      uint8_t saturated = 0;
      if (!block_colour(camera, exposure, shader::project_pinhole(p, kc), !samples, colour, saturated)) continue;
      samples_.push_back({gy * grid_w_ + gx, colour, saturated});
    }
  }
  if (settings_.grey_vote) vote_light_colour();
  for (const Sample& sample : samples_) {
    const int gx = sample.cell % grid_w_, gy = sample.cell / grid_w_;
    const glm::vec3 p = cell(gx, gy);
    const glm::vec3 n_cam = normal_[size_t(sample.cell)];
    const float weight_row = balance_[size_t(sample.cell)];
    const glm::dvec3 colour = sample.colour;
    {
      const glm::vec3 n = rot * n_cam;
      if (samples && known_lamps_.empty()) {
        // A surface the store has seen often enough keeps its transfer: only its colour is new
        // (the visibility search is most of this loop's cost).
        const glm::dvec3 world = glm::dvec3(camera_to_world * glm::dvec4(glm::dvec3(p), 1.0));
        if (samples->observe_if_settled(world, n, bin_[size_t(sample.cell)], colour, weight_row, view.index,
                                        sample.clipped))
          continue;
      }
      ShVector t{};
      for (size_t j = 0; j < directions_.size(); ++j) {
        const glm::vec3& w = directions_[j];
        const float nw = glm::dot(n, w);
        if (nw <= 0.0f) continue;
        const float weight = shader::ssrt_transfer_weight(n, w, visibility(p, rot_t * w, radius), solid_angle);
        if (weight <= 0.0f) continue;
        for (int i = 0; i < kMaxShCoeffs; ++i) t[size_t(i)] += weight * direction_sh_[j][size_t(i)];
      }
      glm::dvec3 known(0.0);
      if (!known_lamps_.empty()) {
        const glm::dvec3 world = glm::dvec3(camera_to_world * glm::dvec4(glm::dvec3(p), 1.0));
        for (const LightDesc& lamp : known_lamps_) {
          glm::dvec3 to_light;
          const glm::dvec3 e = lamp_irradiance(lamp, world, to_light);
          const double cos_n = glm::dot(glm::dvec3(n), to_light);
          if (cos_n <= 0.0) continue;
          const double reach = lamp.type == LightType::Directional
                                   ? double(radius)
                                   : std::min(double(radius), glm::distance(glm::dvec3(lamp.position), world));
          const float k = visibility(p, rot_t * glm::vec3(to_light), float(reach));
          known += e * (cos_n * double(k));
        }
        known *= known_albedo_ / kPi;
      }
      if (samples) {
        const glm::dvec3 world = glm::dvec3(camera_to_world * glm::dvec4(glm::dvec3(p), 1.0));
        samples->observe(world, n, bin_[size_t(sample.cell)], t, colour - known, weight_row, view.index, sample.clipped);
        continue;
      }
      // Rows weighted so that every orientation of surface counts alike (balance_normals).
      const float sw = std::sqrt(weight_row);
      for (float& v : t) v *= sw;
      system.add(t, (colour - known) * double(sw));
    }
  }
  if (samples && samples->distant_enabled() && known_lamps_.empty()) add_distant_views(part, rot, camera, exposure, view.index, *samples);
  return ok_status();
}

namespace {
// Chromaticity (r, g, b) / (r + g + b) of linear RGB; grey for black.
glm::dvec3 chroma_of(const glm::dvec3& c) {
  const double sum = c.x + c.y + c.z;
  return sum > 0.0 ? c / sum : glm::dvec3(1.0 / 3.0);
}
}  // namespace

void ProbelessBuilder::vote_light_colour() {
  // Every sample votes for the light's colour being its own (as if its surface were grey); the
  // colour with the most votes within about 0.02 in (r, g) chromaticity wins (a mode, not
  // gray-world's mean: a red wall or a wooden table beside a grey floor does not tint the light).
  // Samples farther than kChromaOutlier from it keep their luminance but take the winner's
  // colour: their surface is taken as coloured, and their brightness still tells the light's
  // shape. Samples near it keep their own colour, which carries the light's colour by direction
  // (a blue sky and a warm sun). Votes are counted on a 100 x 100 histogram of (r, g), each
  // sample's votes the histogram's sum over the 5 x 5 bins around it: linear in the samples.
  constexpr double kChromaOutlier = 0.04;
  constexpr int kBins = kChromaBins, kReach = 2;
  if (samples_.size() < 2) return;
  std::fill(chroma_hist_.begin(), chroma_hist_.end(), 0);
  auto bin = [](double v) { return std::clamp(int(v * kBins), 0, kBins - 1); };
  for (const Sample& sm : samples_) {
    const glm::dvec3 c = chroma_of(sm.colour);
    ++chroma_hist_[size_t(bin(c.y)) * kBins + size_t(bin(c.x))];
  }
  int best_votes = -1;
  glm::dvec3 winner(1.0 / 3.0);
  for (const Sample& sm : samples_) {
    const glm::dvec3 c = chroma_of(sm.colour);
    const int bx = bin(c.x), by = bin(c.y);
    int votes = 0;
    for (int y = std::max(0, by - kReach); y <= std::min(kBins - 1, by + kReach); ++y)
      for (int x = std::max(0, bx - kReach); x <= std::min(kBins - 1, bx + kReach); ++x)
        votes += chroma_hist_[size_t(y) * kBins + size_t(x)];
    if (votes > best_votes) {
      best_votes = votes;
      winner = c;
    }
  }
  for (Sample& sm : samples_) {
    if (glm::length(chroma_of(sm.colour) - winner) <= kChromaOutlier) continue;
    sm.colour = winner * (sm.colour.x + sm.colour.y + sm.colour.z);
  }
}

}  // namespace mrgi::light
