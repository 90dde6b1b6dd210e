#include "light/env_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <glm/gtc/quaternion.hpp>

namespace mrgi::light {
namespace {

Status check_env_setting(bool ok, const char* field, const std::string& rule) {
  if (ok) return ok_status();
  return fail(ErrorKind::BadUsage, std::string("EnvSamplerSettings.") + field + ": " + rule);
}

bool is_power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

}  // namespace

Expected<EnvSampler> EnvSampler::create(const EnvSamplerSettings& s) {
  MRGI_TRY(check_env_setting(s.grid_width >= 8 && s.grid_width <= 1024 && s.grid_width % 2 == 0,
                       "grid_width", "must be even, 8..1024 cells"));
  MRGI_TRY(check_env_setting(is_power_of_two(s.samples) && s.samples <= 256, "samples",
                       "must be a power of two, 1..256"));
  MRGI_TRY(check_env_setting(s.filter_frames >= 0.0 && std::isfinite(s.filter_frames), "filter_frames",
                       "must be finite and >= 0 frames"));
  MRGI_TRY(check_env_setting(s.source_contrast > 0.0 && std::isfinite(s.source_contrast), "source_contrast",
                             "must be finite and > 0"));
  EnvSampler e(s);
  const int w = s.grid_width, h = w / 2;
  const size_t cells = size_t(w) * size_t(h);
  e.cell_solid_angle_.resize(cells);
  e.cell_sh_.resize(cells);
  e.cell_source_.assign(cells, -1);
  e.source_solid_angle_.reserve(cells);
  e.flood_.reserve(cells);
  for (int y = 0; y < h; ++y) {
    // Exact solid angle of a latitude band cell: (cos theta0 - cos theta1) * 2 pi / w.
    const double t0 = kPi * y / h, t1 = kPi * (y + 1) / h;
    const double dw = (std::cos(t0) - std::cos(t1)) * 2.0 * kPi / w;
    for (int x = 0; x < w; ++x) {
      e.cell_solid_angle_[size_t(y) * w + x] = dw;
      ShVector b = sh_basis(glm::vec3(e.cell_direction(x + 0.5, y + 0.5)));
      for (float& v : b) v *= float(dw);
      e.cell_sh_[size_t(y) * w + x] = b;
    }
  }
  e.cell_sum_.assign(cells, glm::dvec3(0.0));
  e.cell_seen_.assign(cells, 0.0);
  e.radiance_.assign(cells, glm::dvec3(0.0));
  e.moment_.assign(cells, glm::dvec3(0.0));
  e.frame_moment_.assign(cells, glm::dvec3(0.0));
  e.energy_sat_.assign(size_t(w + 1) * size_t(h + 1), 0.0);
  e.lights_.reserve(size_t(s.samples));
  e.light_rects_.reserve(size_t(s.samples) * 2);
  e.light_order_.reserve(size_t(s.samples) * 2);
  e.source_sum_.reserve(cells);
  e.source_moment_.reserve(cells);
  e.cell_excluded_.assign(cells, 0);
  e.regions_.reserve(size_t(s.samples) * 2);
  e.next_regions_.reserve(size_t(s.samples) * 2);
  return e;
}

glm::dvec3 EnvSampler::cell_direction(double x, double y) const {
  const double theta = kPi * y / grid_height();
  const double phi = (x / settings_.grid_width - 0.5) * 2.0 * kPi;
  return glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
}

Status EnvSampler::build_map(const ImageRGBF& image, const EnvCamera& camera,
                             const glm::dquat& env_to_world) {
  const glm::dquat rotation = env_to_world * camera.rotation;
  const bool fisheye = camera.model == EnvModel::FisheyeEquidistant;
  MapKey key{image.width, image.height, camera.model, fisheye ? camera.f : 0.0,
             fisheye ? camera.cx : 0.0, fisheye ? camera.cy : 0.0, fisheye ? camera.fov_deg : 0.0,
             rotation};
  if (have_map_ && key == map_key_) return ok_status();
  const glm::dmat3 rot = glm::mat3_cast(rotation);
  const double half_fov = 0.5 * camera.fov_deg * kPi / 180.0;
  const int w = settings_.grid_width, h = grid_height();
  // A pixel wider than a cell is split into s x s sub-pixels (s from the angle a pixel spans
  // against a cell's), so an image coarser than the grid leaves no cell empty.
  const double cell_angle = 2.0 * kPi / w;
  const double pixel_angle = fisheye ? 1.0 / camera.f : 2.0 * kPi / image.width;
  const int s = std::clamp(int(std::ceil(2.0 * pixel_angle / cell_angle)), 1, 64);
  entries_.clear();
  entries_.reserve(image.pixel_count() * size_t(s) * size_t(s));
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      for (int j = 0; j < s; ++j) {
        for (int i = 0; i < s; ++i) {
          glm::dvec3 d;
          double solid_angle = 0.0;
          if (fisheye) {  // the pixel geometry of light_from_environment (sh_tools.cpp)
            const double dx = u - 0.5 + (i + 0.5) / s - camera.cx, dy = v - 0.5 + (j + 0.5) / s - camera.cy;
            const double r = std::sqrt(dx * dx + dy * dy), theta = r / camera.f;
            if (theta > half_fov) continue;
            const double sn = std::sin(theta);
            d = r > 0.0 ? glm::dvec3(sn * dx / r, sn * dy / r, std::cos(theta)) : glm::dvec3(0, 0, 1);
            // Equidistant: r dr dphi = f^2 theta dtheta dphi and dOmega = sin(theta) dtheta dphi.
            solid_angle = (theta > 1e-9 ? sn / (theta * camera.f * camera.f) : 1.0 / (camera.f * camera.f)) / (s * s);
          } else {
            const double pu = (u + (i + 0.5) / s) / image.width, pv = (v + (j + 0.5) / s) / image.height;
            const double theta = pv * kPi, phi = (pu - 0.5) * 2.0 * kPi;
            d = glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
            solid_angle = std::sin(theta) * (kPi / image.height / s) * (2.0 * kPi / image.width / s);
          }
          const glm::dvec3 world = rot * d;
          const double gu = 0.5 + std::atan2(world.x, -world.z) / (2.0 * kPi);
          const double gv = std::acos(std::clamp(world.y, -1.0, 1.0)) / kPi;
          const int cx = std::clamp(int(gu * w), 0, w - 1), cy = std::clamp(int(gv * h), 0, h - 1);
          entries_.push_back({uint32_t(size_t(v) * size_t(image.width) + size_t(u)), cy * w + cx,
                              float(solid_angle), glm::vec3(world)});
        }
      }
    }
  }
  map_key_ = key;
  have_map_ = true;
  have_history_ = false;  // another geometry: the old grid is no history of this one
  return ok_status();
}

Status EnvSampler::update(const ImageRGBF& image, const EnvCamera& camera,
                          const glm::dquat& env_to_world, double intensity, const glm::dvec3& unseen_radiance) {
  if (image.empty() || image.data.size() != image.pixel_count() * 3)
    return fail(ErrorKind::BadInput, "environment sampling: empty or malformed environment image");
  if (camera.model == EnvModel::FisheyeEquidistant && !(camera.f > 0.0))
    return fail(ErrorKind::BadInput, "environment sampling: fisheye env camera needs f > 0 (pixels)");
  if (!(intensity >= 0.0) || !std::isfinite(intensity))
    return fail(ErrorKind::BadInput, "environment sampling: intensity must be finite and >= 0");
  MRGI_TRY(build_map(image, camera, env_to_world));

  std::fill(cell_sum_.begin(), cell_sum_.end(), glm::dvec3(0.0));
  std::fill(cell_seen_.begin(), cell_seen_.end(), 0.0);
  std::fill(frame_moment_.begin(), frame_moment_.end(), glm::dvec3(0.0));
  const float* px = image.data.data();
  for (const MapEntry& e : entries_) {
    const float* t = px + 3 * size_t(e.pixel);
    glm::dvec3 l(t[0], t[1], t[2]);
    for (int i = 0; i < 3; ++i)
      if (!(l[i] >= 0.0) || std::isinf(l[i])) l[i] = 0.0;
    const double dw = e.solid_angle;
    const size_t c = size_t(e.cell);
    cell_sum_[c] += l * (intensity * dw);
    cell_seen_[c] += dw;
    // The energy-weighted direction of what falls into the cell: a light then sits where its
    // light is, not at its cells' centres.
    frame_moment_[c] += (luminance(l) * intensity * dw) * glm::dvec3(e.direction);
  }
  const int w = settings_.grid_width, h = grid_height();
  const double alpha = have_history_ && settings_.filter_frames > 0.0
                           ? 1.0 - std::exp(-1.0 / settings_.filter_frames)
                           : 1.0;
  for (size_t c = 0; c < size_t(w) * size_t(h); ++c) {
    const glm::dvec3 l = cell_seen_[c] > 0.0 ? cell_sum_[c] / cell_seen_[c] : unseen_radiance;
    radiance_[c] += alpha * (l - radiance_[c]);
    // The moment scales with the cell's coverage; normalised to a full cell like the radiance.
    const glm::dvec3 m = cell_seen_[c] > 0.0 ? frame_moment_[c] * (cell_solid_angle_[c] / cell_seen_[c])
                                             : glm::dvec3(0.0);
    moment_[c] += alpha * (m - moment_[c]);
  }
  have_history_ = true;

  sh_ = ShRgb{};
  for (size_t c = 0; c < size_t(w) * size_t(h); ++c) {
    if (radiance_[c] == glm::dvec3(0.0)) continue;
    for (int i = 0; i < kMaxShCoeffs; ++i) sh_[size_t(i)] += radiance_[c] * double(cell_sh_[c][size_t(i)]);
  }
  cut();
  return ok_status();
}

double EnvSampler::rect_energy(const RegionRect& r) const {
  const size_t stride = size_t(settings_.grid_width + 1);
  auto sat = [&](int x, int y) { return energy_sat_[size_t(y) * stride + size_t(x)]; };
  return sat(r.x1, r.y1) - sat(r.x0, r.y1) - sat(r.x1, r.y0) + sat(r.x0, r.y0);
}

bool EnvSampler::split_rect(const RegionRect& r, RegionRect& a, RegionRect& b) const {
  const int nx = r.x1 - r.x0, ny = r.y1 - r.y0;
  if (nx == 1 && ny == 1) return false;
  // Angular extents: a row of cells narrows with sin(theta) towards the poles (Debevec's
  // cos(latitude) scaling of the width).
  const int h = grid_height();
  const double mid_theta = kPi * 0.5 * (r.y0 + r.y1) / h;
  const double width = nx * (2.0 * kPi / settings_.grid_width) * std::sin(mid_theta), height = ny * (kPi / h);
  const bool split_x = ny == 1 || (nx > 1 && width >= height);
  const int lo = split_x ? r.x0 : r.y0, hi = split_x ? r.x1 : r.y1;
  const double total = rect_energy(r);
  int at = (lo + hi) / 2;
  if (total > 0.0) {
    double best = 1e300;
    for (int k = lo + 1; k < hi; ++k) {
      const double part = split_x ? rect_energy({r.x0, k, r.y0, r.y1}) : rect_energy({r.x0, r.x1, r.y0, k});
      const double diff = std::abs(part - 0.5 * total);
      if (diff < best) {
        best = diff;
        at = k;
      }
    }
  }
  a = split_x ? RegionRect{r.x0, at, r.y0, r.y1} : RegionRect{r.x0, r.x1, r.y0, at};
  b = split_x ? RegionRect{at, r.x1, r.y0, r.y1} : RegionRect{r.x0, r.x1, at, r.y1};
  return true;
}

// The region's light: its irradiance and solid angle summed, at its energy-weighted mean
// direction (the rect's centre when it holds none).
void EnvSampler::collapse(const RegionRect& r, EnvLight& l, bool with_sh) const {
  const int w = settings_.grid_width;
  glm::dvec3 moment(0.0);
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t c = size_t(y) * w + x;
      l.irradiance += radiance_[c] * cell_solid_angle_[c];
      l.solid_angle_sr += cell_solid_angle_[c];
      if (luminance(radiance_[c]) > 0.0) l.lit_solid_angle_sr += cell_solid_angle_[c];
      moment += moment_[c];
      if (with_sh)
        for (int i = 0; i < kMaxShCoeffs; ++i) l.region_sh[size_t(i)] += radiance_[c] * double(cell_sh_[c][size_t(i)]);
    }
  }
  const double len = glm::length(moment);
  l.direction = len > 0.0 && std::isfinite(len) ? moment / len
                                                : cell_direction(0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
}

void EnvSampler::cut() {
  const int w = settings_.grid_width, h = grid_height();
  // Summed-area table of the energy (luminance x solid angle) for O(1) region sums.
  auto sat = [&](int x, int y) -> double& { return energy_sat_[size_t(y) * size_t(w + 1) + size_t(x)]; };
  for (int y = 0; y < h; ++y) {
    double row = 0.0;
    for (int x = 0; x < w; ++x) {
      const size_t c = size_t(y) * w + x;
      row += luminance(radiance_[c]) * cell_solid_angle_[c];
      sat(x + 1, y + 1) = sat(x + 1, y) + row;
    }
  }
  regions_.clear();
  regions_.push_back({0, w, 0, h});
  for (int level = 1; level < settings_.samples; level *= 2) {
    next_regions_.clear();
    for (const RegionRect& r : regions_) {
      RegionRect a{}, b{};
      if (!split_rect(r, a, b)) {
        next_regions_.push_back(r);
        continue;
      }
      next_regions_.push_back(a);
      next_regions_.push_back(b);
    }
    std::swap(regions_, next_regions_);
  }
  double lit = 0.0;
  for (size_t c = 0; c < radiance_.size(); ++c)
    if (luminance(radiance_[c]) > 0.0) lit += cell_solid_angle_[c];
  mean_lit_luminance_ = lit > 0.0 ? sat(w, h) / lit : 0.0;
  find_sources();
  lights_.clear();
  for (const RegionRect& r : regions_) {
    EnvLight l;
    collapse(r, l, true);
    double brightest = -1.0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t c = size_t(y) * w + x;
        if (const double lum = luminance(radiance_[c]); lum > brightest) {
          brightest = lum;
          l.source_solid_angle_sr = cell_source_[c] >= 0 ? source_solid_angle_[size_t(cell_source_[c])] : 0.0;
        }
      }
    lights_.push_back(l);
  }
  // Strongest first; light_rects_ follows the same order.
  light_order_.clear();
  for (size_t i = 0; i < lights_.size(); ++i) light_order_.push_back(i);
  std::stable_sort(light_order_.begin(), light_order_.end(), [&](size_t a, size_t b) {
    return luminance(lights_[a].irradiance) > luminance(lights_[b].irradiance);
  });
  light_rects_.clear();
  for (size_t i : light_order_) light_rects_.push_back(regions_[i]);
  std::stable_sort(lights_.begin(), lights_.end(), [](const EnvLight& a, const EnvLight& b) {
    return luminance(a.irradiance) > luminance(b.irradiance);
  });
}

int EnvSampler::split_light(size_t index, int parts, EnvPart* out) const {
  if (index >= light_rects_.size() || parts < 1 || (parts & (parts - 1)) != 0) return 0;
  // Breadth-first halving of the region, as the cut's: rects[0, n) each with its share of the
  // region's light (1, or halved where a single cell stands in for both halves). A fixed array:
  // nothing is allocated per frame.
  constexpr int kMost = 64;
  parts = std::min(parts, kMost);
  std::array<RegionRect, kMost> rects{};
  std::array<double, kMost> share{};
  rects[0] = light_rects_[index];
  share[0] = 1.0;
  for (int n = 1; n < parts; n *= 2) {
    for (int i = n - 1; i >= 0; --i) {
      RegionRect a{}, b{};
      if (split_rect(rects[size_t(i)], a, b)) {
        rects[size_t(2 * i)] = a;
        rects[size_t(2 * i + 1)] = b;
        share[size_t(2 * i + 1)] = share[size_t(i)];
      } else {
        rects[size_t(2 * i + 1)] = rects[size_t(i)];
        rects[size_t(2 * i)] = rects[size_t(i)];
        share[size_t(2 * i + 1)] = share[size_t(i)] *= 0.5;
      }
      share[size_t(2 * i)] = share[size_t(i)];
    }
  }
  for (int i = 0; i < parts; ++i) {
    EnvLight l;
    collapse(rects[size_t(i)], l, false);
    out[i].direction = l.direction;
    out[i].irradiance = l.irradiance * share[size_t(i)];
    out[i].solid_angle_sr = l.solid_angle_sr * share[size_t(i)];
  }
  return parts;
}

void EnvSampler::sources_outside(const std::vector<size_t>& excluded, size_t count, std::vector<EnvSource>& out) const {
  out.clear();
  const size_t sources = source_solid_angle_.size();
  if (sources == 0 || count == 0) return;
  const int w = settings_.grid_width;
  std::fill(cell_excluded_.begin(), cell_excluded_.end(), uint8_t(0));
  for (size_t k : excluded) {
    if (k >= light_rects_.size()) continue;
    const RegionRect& r = light_rects_[k];
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) cell_excluded_[size_t(y) * w + x] = 1;
  }
  source_sum_.assign(sources, EnvSource{});
  source_moment_.assign(sources, glm::dvec3(0.0));
  for (size_t c = 0; c < cell_source_.size(); ++c) {
    if (cell_source_[c] < 0 || cell_excluded_[c]) continue;
    EnvSource& s = source_sum_[size_t(cell_source_[c])];
    s.irradiance += radiance_[c] * cell_solid_angle_[c];
    s.solid_angle_sr += cell_solid_angle_[c];
    source_moment_[size_t(cell_source_[c])] += moment_[c];
    for (int i = 0; i < kMaxShCoeffs; ++i) s.sh[size_t(i)] += radiance_[c] * double(cell_sh_[c][size_t(i)]);
  }
  for (size_t i = 0; i < sources; ++i) {
    EnvSource& s = source_sum_[i];
    const double len = glm::length(source_moment_[i]);
    if (!(s.solid_angle_sr > 0.0) || !(luminance(s.irradiance) > 0.0) || !(len > 0.0) || !std::isfinite(len)) continue;
    s.direction = source_moment_[i] / len;
    // Keep the `count` strongest: insertion into the sorted list.
    if (out.size() == count && luminance(out.back().irradiance) >= luminance(s.irradiance)) continue;
    if (out.size() == count) out.pop_back();
    auto at = std::find_if(out.begin(), out.end(), [&](const EnvSource& o) {
      return luminance(o.irradiance) < luminance(s.irradiance);
    });
    out.insert(at, s);
  }
}

void EnvSampler::find_sources() {
  const int w = settings_.grid_width, h = grid_height();
  const double threshold = settings_.source_contrast * mean_lit_luminance_;
  std::fill(cell_source_.begin(), cell_source_.end(), -1);
  source_solid_angle_.clear();
  if (!(mean_lit_luminance_ > 0.0)) return;
  auto bright = [&](size_t c) { return luminance(radiance_[c]) >= threshold; };
  for (size_t start = 0; start < cell_source_.size(); ++start) {
    if (cell_source_[start] >= 0 || !bright(start)) continue;
    const int32_t id = int32_t(source_solid_angle_.size());
    double energy = 0.0, peak = 0.0;
    flood_.clear();
    flood_.push_back(int32_t(start));
    cell_source_[start] = id;
    while (!flood_.empty()) {
      const int32_t c = flood_.back();
      flood_.pop_back();
      const double lum = luminance(radiance_[size_t(c)]);
      energy += lum * cell_solid_angle_[size_t(c)];
      peak = std::max(peak, lum);
      const int cx = c % w, cy = c / w;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int ny = cy + dy;
          if ((dx == 0 && dy == 0) || ny < 0 || ny >= h) continue;
          const size_t n = size_t(ny) * w + size_t((cx + dx + w) % w);  // azimuth wraps
          if (cell_source_[n] >= 0 || !bright(n)) continue;
          cell_source_[n] = id;
          flood_.push_back(int32_t(n));
        }
    }
    // Its energy over its peak radiance: the solid angle of a uniform source of that peak, which
    // the cells it only partly covers do not inflate (a 3-degree sun on 5.6-degree cells).
    source_solid_angle_.push_back(peak > 0.0 ? energy / peak : 0.0);
  }
}

size_t EnvSampler::cone_pyramid_cells(int width, int levels) {
  size_t cells = 0;
  for (int l = 0; l < levels && (width >> l) >= 4; ++l) cells += size_t(width >> l) * size_t((width >> l) / 2);
  return cells;
}

int EnvSampler::cone_pyramid(int levels, std::vector<glm::vec4>& out) const {
  const int w0 = settings_.grid_width;
  out.resize(cone_pyramid_cells(w0, levels));
  for (size_t i = 0; i < radiance_.size(); ++i) out[i] = glm::vec4(glm::vec3(radiance_[i]), 0.0f);
  size_t first = 0;
  int written = 1;
  for (int l = 1; l < levels && (w0 >> l) >= 4; ++l, ++written) {
    const int w = w0 >> l, h = w / 2, wp = w0 >> (l - 1);
    const size_t next = first + size_t(wp) * size_t(wp / 2);
    for (int y = 0; y < h; ++y) {
      // A row's solid angle is proportional to the sine of its colatitude.
      const double s0 = std::sin((2 * y + 0.5) * kPi / (2 * h)), s1 = std::sin((2 * y + 1.5) * kPi / (2 * h));
      for (int x = 0; x < w; ++x) {
        const glm::vec4 a = out[first + size_t(2 * y) * wp + size_t(2 * x)] + out[first + size_t(2 * y) * wp + size_t(2 * x + 1)];
        const glm::vec4 b = out[first + size_t(2 * y + 1) * wp + size_t(2 * x)] + out[first + size_t(2 * y + 1) * wp + size_t(2 * x + 1)];
        out[next + size_t(y) * w + size_t(x)] = (a * float(s0) + b * float(s1)) / float(2.0 * (s0 + s1));
      }
    }
    first = next;
  }
  return written;
}

}  // namespace mrgi::light
