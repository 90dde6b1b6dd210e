#include "light/light_stage.h"

#include <functional>

#include "light/camera_color.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/quaternion.hpp>

#include "light/sh_tools.h"
#include "mrgi/metrics.h"
#include "shared/mrgi_shared.h"

namespace mrgi::light {
namespace {

// A cone of the ambient for the objects' occlusion: its direction, light, and the cone of its
// solid angle (at most a hemisphere).
Lighting::AmbientRegion ambient_region(const glm::dvec3& direction, const glm::dvec3& irradiance, double solid_angle_sr,
                                       const ShRgb& sh) {
  Lighting::AmbientRegion a;
  a.direction = direction;
  a.irradiance = irradiance;
  a.half_angle_rad = std::acos(std::clamp(1.0 - solid_angle_sr / (2.0 * kPi), 0.0, 1.0));
  a.sh = sh;
  return a;
}

// The cone of the near lamp's stand-in spot (set_probeless_lighting): full light within 50 degrees
// of the virtual objects' direction, none beyond 60 (a 120-degree shadow frustum).
constexpr double kNearLampInnerDeg = 50.0, kNearLampOuterDeg = 60.0;
// Successive near-lamp fits closer than this are the same lamp, and move it this fraction.
constexpr double kSameLampM = 0.5, kLampSmoothing = 0.3, kKeepLampResidual = 0.75;
constexpr int kAlbedoFits = 16, kAlbedoSettleFits = 4;
constexpr double kAlbedoGrowth = 1.1;

// The lights' colour and intensity in scene.json's convention: colour times intensity per
// channel, the colour's largest channel 1.
void set_rgb(LightDesc& l, const glm::dvec3& rgb) {
  const double peak = std::max({rgb.x, rgb.y, rgb.z, 0.0});
  l.intensity = float(peak);
  l.color = peak > 0.0 ? glm::vec3(rgb / peak) : glm::vec3(1.0f);
}

}  // namespace

const char* source_name(LightSourceKind kind) {
  switch (kind) {
    case LightSourceKind::Declared: return "declared lamps";
    case LightSourceKind::Environment: return "environment image";
    case LightSourceKind::Probeless: return "probeless estimate";
    case LightSourceKind::None: break;
  }
  return "none";
}

std::array<glm::mat4, 3> irradiance_matrices(const ShRgb& l) {
  // Basis polynomials of shaders/shared/mrgi_shared.h sh_basis16 (bands 0..2).
  constexpr double c0 = 0.282094791773878, c1 = 0.488602511902920, c2 = 1.092548430592079,
                   c3 = 0.315391565252520, c4 = 0.546274215296040;
  constexpr double a0 = kPi, a1 = 2.0 * kPi / 3.0, a2 = kPi / 4.0;
  std::array<glm::mat4, 3> out{};
  for (int c = 0; c < 3; ++c) {
    double e[9];
    for (int i = 0; i < 9; ++i) e[i] = (i == 0 ? a0 : i < 4 ? a1 : a2) * l[size_t(i)][c];
    glm::dmat4 m(0.0);  // m[col][row], symmetric; rows/cols x y z 1
    m[0][0] = c4 * e[8];
    m[1][1] = -c4 * e[8];
    m[2][2] = 3.0 * c3 * e[6];
    m[3][3] = c0 * e[0] - c3 * e[6];
    m[0][1] = m[1][0] = 0.5 * c2 * e[4];
    m[1][2] = m[2][1] = -0.5 * c2 * e[5];
    m[0][2] = m[2][0] = -0.5 * c2 * e[7];
    m[0][3] = m[3][0] = -0.5 * c1 * e[3];
    m[1][3] = m[3][1] = -0.5 * c1 * e[1];
    m[2][3] = m[3][2] = 0.5 * c1 * e[2];
    out[size_t(c)] = glm::mat4(m);
  }
  return out;
}

Expected<std::unique_ptr<LightStage>> LightStage::create(const LightStageSettings& settings,
                                                         const SceneDesc& scene, const CameraSetup& cameras) {
  if (settings.shadowed_environment_lights < 0 || settings.shadowed_environment_lights > kMaxStageLights)
    return fail(ErrorKind::BadUsage, "LightStageSettings.shadowed_environment_lights: must be 0..8");
  if (!(settings.shadowed_min_contrast >= 0.0) || !(settings.shadowed_max_solid_angle_sr > 0.0))
    return fail(ErrorKind::BadUsage, "LightStageSettings.shadowed_min_contrast must be >= 0 and "
                                     "shadowed_max_solid_angle_sr > 0");
  if (!(settings.occlusion_region_min_contrast >= 0.0))
    return fail(ErrorKind::BadUsage, "LightStageSettings.occlusion_region_min_contrast must be >= 0");
  const LampRemovalSettings& lr = settings.lamp_removal;
  if (!(lr.contrast > 0.0) || !(lr.search_deg > 0.0) || !(lr.max_deg > 0.0) || !(lr.ring_inner_deg > 0.0) ||
      !(lr.ring_outer_deg > lr.ring_inner_deg))
    return fail(ErrorKind::BadUsage, "LightStageSettings.lamp_removal: contrast and the angles must be > 0, "
                                     "ring_outer_deg > ring_inner_deg");
  if (!(settings.near_field_distance_m >= 0.0) || !(settings.near_field_step_m > 0.0) ||
      !(settings.near_field_tolerance_m >= 0.0))
    return fail(ErrorKind::BadUsage, "LightStageSettings.near_field_distance_m and near_field_tolerance_m must be "
                                     ">= 0 and near_field_step_m > 0");
  if (settings.residual_shading_bands < 1 || settings.residual_shading_bands > 3)
    return fail(ErrorKind::BadUsage, "LightStageSettings.residual_shading_bands: must be 1..3");
  if (auto check = LightEstimator::create(settings.external_estimator); !check) return check.error();
  auto stage = std::unique_ptr<LightStage>(new LightStage());
  LightStage& s = *stage;
  s.settings_ = settings;
  s.scene_ = scene;
  s.cameras_ = cameras;
  s.declared_ = int(scene.lights.size());
  if (s.declared_ > kMaxStageLights)
    return fail(ErrorKind::BadInput, scene.path + ": lights: " + std::to_string(s.declared_) +
                                         " lamps, at most " + std::to_string(kMaxStageLights));
  s.planned_ = scene.environment.present ? LightSourceKind::Environment
                                         : (s.declared_ > 0 ? LightSourceKind::Declared : LightSourceKind::Probeless);
  for (const LightDesc& l : scene.lights)
    if (l.real) s.real_lamps_.push_back(l);
  s.lamp_removal_ = LampRemoval(settings.lamp_removal);
  s.residual_ = s.planned_ == LightSourceKind::Declared && settings.residual_light && !s.real_lamps_.empty();
  auto estimator = LightEstimator::create(s.residual_ ? settings.residual_estimator : settings.estimator);
  if (!estimator) return estimator.error();
  s.estimator_.emplace(std::move(*estimator));
  const EnvironmentDesc& env = scene.environment;
  if (env.present) {
    auto sampler = EnvSampler::create(settings.environment);
    if (!sampler) return sampler.error();
    s.env_.emplace(std::move(*sampler));
    s.env_lights_ = std::min(settings.shadowed_environment_lights, kMaxStageLights - s.declared_);
    s.shadowed_regions_.reserve(size_t(std::max(s.env_lights_, 0)));
    s.near_.reserve(size_t(settings.environment.samples));
    if (!env.from_env_camera) {  // a file: sampled once, here
      auto img = load_hdr_image(env.image);
      if (!img) return img.error();
      MRGI_TRY(s.env_->update(*img, EnvCamera{}, glm::dquat(env.rotation), env.intensity));
      s.env_from_file_ = true;
    }
  }
  if (s.planned_ == LightSourceKind::Probeless || s.residual_) {
    auto b = ProbelessBuilder::create(s.residual_ ? settings.residual_probeless : settings.probeless,
                                      cameras.color, cameras.depth, cameras.depth_scale);
    if (!b) return b.error();
    s.probeless_.emplace(std::move(*b));
    if (s.residual_) s.probeless_->set_known_lamps(s.real_lamps_, settings.estimator.gray_albedo);
    if (!s.residual_ && settings.samples.enabled) {
      auto store = RadianceSamples::create(settings.samples);
      if (!store) return store.error();
      s.samples_.emplace(std::move(*store));
      if (settings.point_lamp.enabled) s.lamp_fitter_.emplace(settings.point_lamp);
      if (settings.albedo_fit.enabled) {
        AlbedoFitSettings fit = settings.albedo_fit;
        fit.near_field_emitters = settings.samples.capacity;  // the near field reads every sample
        s.albedo_fitter_.emplace(fit);
        s.near_field_on_ = settings.near_field;
        s.direct_samples_.reserve(size_t(std::max(16, settings.albedo_fit.receivers)));
      }
    }
  }
  s.max_lights_ = s.declared_ + s.env_lights_ + (s.planned_ == LightSourceKind::Probeless ? 1 : 0);
  s.lighting_.lights.reserve(kMaxStageLights);
  s.last_env_directions_.reserve(kMaxStageLights);
  s.lighting_.light_sh.reserve(kMaxStageLights);
  s.lighting_.foldable.reserve(kMaxStageLights);
  s.lighting_.ambient_regions.reserve(Lighting::kMaxOcclusionRegions);
  s.region_order_.reserve(size_t(settings.environment.samples));  // one entry a region at most
  s.sources_.reserve(size_t(Lighting::kMaxOcclusionRegions));
  for (const LightDesc& l : scene.lights) {
    s.lighting_.lights.push_back(l);
    s.lighting_.light_sh.push_back(ShRgb{});
    s.lighting_.foldable.push_back(0);
  }
  s.update_declared_sh();
  s.lighting_.source = s.planned_;
  s.lighting_.environment = env.present;
  if (s.planned_ == LightSourceKind::Probeless) s.set_probeless_lighting();
  else if (s.env_from_file_) s.set_environment_lighting(env.real);
  else s.finish_declared();
  return stage;
}

void LightStage::update_declared_sh() {
  // The declared real lamps seen from the focus, for the exported estimate.
  declared_sh_ = ShRgb{};
  for (const LightDesc& l : scene_.lights) {
    if (!l.real) continue;
    glm::dvec3 to_light;
    const glm::dvec3 e = lamp_irradiance(l, glm::dvec3(settings_.focus), to_light);
    const ShRgb sh = sh_directional_light(to_light, e);
    for (int i = 0; i < kMaxShCoeffs; ++i) declared_sh_[size_t(i)] += sh[size_t(i)];
  }
}

Status LightStage::set_declared_lamp(size_t i, const LightDesc& lamp) {
  const std::string where = "lamp " + std::to_string(i);
  if (i >= size_t(declared_))
    return fail(ErrorKind::BadUsage, where + ": the scene declares " + std::to_string(declared_) + " (indices from 0)");
  const LightDesc& was = scene_.lights[i];
  if (lamp.type != was.type || lamp.real != was.real)
    return fail(ErrorKind::BadUsage, where + ": type and real cannot change (its shadow maps were laid out for them)");
  auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite3(lamp.position) || !finite3(lamp.direction) || !finite3(lamp.color) || !std::isfinite(lamp.intensity))
    return fail(ErrorKind::BadUsage, where + ": position, direction, color and intensity must be finite");
  if (lamp.type != LightType::Point && !(glm::length(lamp.direction) > 1e-9f))
    return fail(ErrorKind::BadUsage, where + ".direction: must be non-zero");
  if (lamp.color.x < 0.0f || lamp.color.y < 0.0f || lamp.color.z < 0.0f || lamp.intensity < 0.0f)
    return fail(ErrorKind::BadUsage, where + ": color and intensity must be >= 0");
  if (lamp.type == LightType::Spot &&
      !(lamp.inner_angle_deg >= 0.0f && lamp.inner_angle_deg <= lamp.outer_angle_deg && lamp.outer_angle_deg <= 90.0f))
    return fail(ErrorKind::BadUsage, where + ": spot angles must satisfy 0 <= inner_angle_deg <= outer_angle_deg <= 90");
  LightDesc l = lamp;
  if (l.type != LightType::Point) l.direction = glm::normalize(l.direction);
  scene_.lights[i] = l;
  // Under the probeless source (a technique's own estimate, use_external_system) the lamps
  // light nothing: kept for when they are asked for, the frame's light left as it is.
  if (planned_ == LightSourceKind::Probeless) return ok_status();
  lighting_.lights[i] = l;
  size_t r = 0;
  for (const LightDesc& d : scene_.lights)
    if (d.real) real_lamps_[r++] = d;
  if (residual_) probeless_->set_known_lamps(real_lamps_, settings_.estimator.gray_albedo);
  update_declared_sh();
  ++lighting_.revision;
  finish_declared();
  return ok_status();
}

void LightStage::finish_declared() {
  ShRgb all = declared_sh_;
  if (residual_)
    for (int i = 0; i < kMaxShCoeffs; ++i) all[size_t(i)] += lighting_.ambient_real[size_t(i)];
  if (lighting_.environment && scene_.environment.real && env_ && env_->valid())
    for (int i = 0; i < kMaxShCoeffs; ++i) all[size_t(i)] += env_->radiance_sh()[size_t(i)];
  LightEstimate& e = lighting_.estimate;
  const int64_t frame = e.frame_index;
  const double t = e.timestamp;
  e = LightEstimate{};
  fill_light_estimate(all, kMaxShBands, e);
  e.valid = declared_ > 0 || (env_ && env_->valid());
  e.confidence = 1.0f;
  e.frame_index = frame;
  e.timestamp = t;
}

const std::vector<EnvLight>& LightStage::environment_regions() const {
  static const std::vector<EnvLight> none;
  return lighting_.environment && env_ && env_->valid() ? env_->lights() : none;
}

glm::dvec3 LightStage::mean_camera_radiance(const frame::CameraView& camera) const {
  const CameraColor c(camera);
  if (c.empty() || !(cameras_.exposure > 0.0)) return glm::dvec3(0.0);
  glm::dvec3 sum(0.0);
  size_t n = 0;
  for (int y = 4; y < c.height(); y += 8)
    for (int x = 4; x < c.width(); x += 8) {
      const std::array<uint8_t, 3> p = c.at(x, y);
      sum += glm::dvec3(srgb8_to_linear(p[0]), srgb8_to_linear(p[1]), srgb8_to_linear(p[2]));
      ++n;
    }
  return n ? sum / (double(n) * cameras_.exposure) : glm::dvec3(0.0);
}

bool LightStage::crosses_surface(const glm::dvec3& from, const glm::dvec3& direction, const frame::DepthView& depth,
                                 const glm::dmat4& world_to_camera) const {
  const Intrinsics& k = cameras_.depth;
  const double scale = cameras_.depth_scale;
  bool in_front = false;
  const double step = std::max(settings_.near_field_step_m, 1e-3);
  for (double t = step; t <= settings_.near_field_distance_m; t += step) {
    const glm::dvec3 p = glm::dvec3(world_to_camera * glm::dvec4(from + direction * t, 1.0));
    if (!(p.z > 0.05)) continue;
    const int u = int(std::lround(k.fx * p.x / p.z + k.cx)), v = int(std::lround(k.fy * p.y / p.z + k.cy));
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) continue;
    const uint16_t raw = depth.at(u, v);
    if (raw == 0) continue;
    const double measured = double(raw) / scale;
    if (p.z < measured - settings_.near_field_tolerance_m) {
      in_front = true;
    } else if (in_front && p.z > measured + settings_.near_field_tolerance_m) {
      return true;  // passed behind the surface the depth camera sees: the ray met it
    }
  }
  return false;
}

void LightStage::mark_near_regions(const frame::CameraView& camera) {
  near_.assign(env_->lights().size(), 0);
  const std::optional<EnvCamera>& cam = cameras_.env_camera;
  if (!cam || !cam->position || camera.depth.empty() || !(settings_.near_field_distance_m > 0.0)) return;
  const glm::dmat4 world_to_camera = glm::inverse(camera.camera_to_world);
  // Only the candidates (compact and bright) need the march.
  for (size_t k = 0; k < env_->lights().size(); ++k) {
    const EnvLight& r = env_->lights()[k];
    if (!shadowable_region(r, env_->mean_lit_luminance())) continue;
    near_[k] = crosses_surface(*cam->position, r.direction, camera.depth, world_to_camera) ? 1 : 0;
  }
}

bool LightStage::shadowable_region(const EnvLight& r, double mean_luminance) const {
  if (!(r.lit_solid_angle_sr > 0.0) || !(mean_luminance > 0.0)) return false;
  const double contrast = luminance(r.irradiance) / r.lit_solid_angle_sr / mean_luminance;
  return contrast >= settings_.shadowed_min_contrast && r.source_solid_angle_sr > 0.0 &&
         r.source_solid_angle_sr <= settings_.shadowed_max_solid_angle_sr;
}

void LightStage::set_environment_lighting(bool real) {
  // Lamps first (unchanged), then the strongest compact, bright, distant regions as shadowed
  // directional lights; the SH of the other regions is the ambient.
  lighting_.lights.resize(size_t(declared_));
  lighting_.light_sh.resize(size_t(declared_));
  lighting_.foldable.resize(size_t(declared_));
  ShRgb ambient = env_->radiance_sh();
  const auto& regions = env_->lights();
  // The strongest regions that are compact and bright (LightStageSettings::
  // shadowed_min_contrast), up to env_lights_.
  shadowed_regions_.clear();
  for (size_t k = 0; k < regions.size() && int(shadowed_regions_.size()) < env_lights_; ++k)
    if (shadowable_region(regions[k], env_->mean_lit_luminance()) && !(k < near_.size() && near_[k]))
      shadowed_regions_.push_back(k);
  bool changed = last_env_directions_.size() != shadowed_regions_.size();
  last_env_directions_.resize(shadowed_regions_.size());
  for (size_t k = 0; k < shadowed_regions_.size(); ++k) {
    const EnvLight& r = regions[shadowed_regions_[k]];
    LightDesc l;
    l.type = LightType::Directional;
    l.real = real;
    l.direction = glm::vec3(-r.direction);
    set_rgb(l, r.irradiance);
    lighting_.lights.push_back(l);
    lighting_.light_sh.push_back(r.region_sh);
    lighting_.foldable.push_back(1);
    for (int i = 0; i < kMaxShCoeffs; ++i) ambient[size_t(i)] -= r.region_sh[size_t(i)];
    changed = changed || last_env_directions_[k] != r.direction;
    last_env_directions_[k] = r.direction;
  }
  lighting_.ambient_real = real ? ambient : ShRgb{};
  lighting_.ambient_virtual = real ? ShRgb{} : ambient;
  set_ambient_regions();
  if (changed) ++lighting_.revision;
  finish_declared();
}

void LightStage::set_ambient_regions() {
  // The regions not drawn as lights, brighter than the environment's mean by the stated
  // contrast, most concentrated (highest mean radiance) first.
  lighting_.ambient_regions.clear();
  const auto& regions = env_->lights();
  const double mean = env_->mean_lit_luminance();
  if (!(mean > 0.0)) return;
  if (settings_.occlusion_regions_from_sources) {
    env_->sources_outside(shadowed_regions_, size_t(Lighting::kMaxOcclusionRegions), sources_);
    for (const EnvSource& src : sources_)
      if (luminance(src.irradiance) / src.solid_angle_sr / mean >= settings_.occlusion_region_min_contrast)
        lighting_.ambient_regions.push_back(ambient_region(src.direction, src.irradiance, src.solid_angle_sr, src.sh));
    return;
  }
  region_order_.clear();
  for (size_t k = 0; k < regions.size(); ++k) {
    const EnvLight& r = regions[k];
    if (std::find(shadowed_regions_.begin(), shadowed_regions_.end(), k) != shadowed_regions_.end()) continue;
    if (!(r.solid_angle_sr > 0.0) || !(r.lit_solid_angle_sr > 0.0)) continue;
    const double contrast = luminance(r.irradiance) / r.lit_solid_angle_sr / mean;
    if (contrast >= settings_.occlusion_region_min_contrast) region_order_.emplace_back(contrast, k);
  }
  std::sort(region_order_.begin(), region_order_.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; i < region_order_.size() && i < size_t(Lighting::kMaxOcclusionRegions); ++i) {
    const EnvLight& r = regions[region_order_[i].second];
    lighting_.ambient_regions.push_back(ambient_region(r.direction, r.irradiance, r.solid_angle_sr, r.region_sh));
  }
}

void LightStage::set_probeless_lighting() {
  lighting_.ambient_holds_real_bounce = true;
  const LightEstimate& est = estimator_->estimate();
  const ShRgb& l = estimator_->filtered();
  // The near field (the light the kept surfaces send to the focus, albedo_fit.h) is unshadowed
  // ambient: the dominant light and its shadow come from the distant light alone. The distant
  // ambient stays whole here, though the surfaces in front of the focus hide part of it (the
  // exported estimate takes that part off, add_near_field): rendered with it taken off, the
  // moving family's tuning half read worse in every scene (RDE ratio median / worst 1.22 / 1.44
  // -> 1.38 / 1.61).
  const bool near = near_field_on_ && near_field_valid_;
  auto with_near_field = [&](const ShRgb& distant) {
    if (!near) return distant;
    ShRgb out = distant;
    for (int i = 0; i < kMaxShCoeffs; ++i) out[size_t(i)] += near_field_[size_t(i)];
    return out;
  };
  lighting_.lights.clear();
  lighting_.light_sh.clear();
  lighting_.foldable.clear();
  ShRgb ambient = l;
  glm::dvec3 dir;
  if (est.valid && lamp_.found) {
    // A near lamp: a shadowed light where it was found, a wide spot aimed at the virtual objects'
    // centre (the focus), so it takes one shadow map layer as the distant light it stands in
    // for does (a point lamp's six would overrun what was allocated for the probeless source);
    // the estimate is exported with the lamp as the focus sees it added to the SH of the rest.
    const glm::dvec3 v = lamp_.position - glm::dvec3(settings_.focus);
    const double d2 = std::max(glm::dot(v, v), 1e-4);
    const glm::dvec3 to_lamp = v / std::sqrt(d2);
    LightDesc p;
    p.type = LightType::Spot;
    p.real = true;
    p.position = glm::vec3(lamp_.position);
    p.direction = glm::vec3(-to_lamp);
    p.inner_angle_deg = float(kNearLampInnerDeg);
    p.outer_angle_deg = float(kNearLampOuterDeg);
    set_rgb(p, lamp_.intensity);
    const ShRgb sh = sh_directional_light(to_lamp, lamp_.intensity / d2);
    lighting_.lights.push_back(p);
    lighting_.light_sh.push_back(sh);
    lighting_.foldable.push_back(0);
    ShRgb all = l;
    for (int i = 0; i < kMaxShCoeffs; ++i) all[size_t(i)] += sh[size_t(i)];
    lighting_.ambient_real = with_near_field(ambient);
    lighting_.ambient_virtual = ShRgb{};
    lighting_.ambient_regions.clear();
    lighting_.estimate = est;
    fill_light_estimate(all, est.bands, lighting_.estimate);
    if (near) add_near_field(lighting_.estimate, l);
    ++lighting_.revision;
    return;
  }
  if (est.valid && sh_dominant_direction(l, dir)) {
    const glm::dvec3 e = sh_dominant_intensity(l, dir);
    if (luminance(e) > 0.0) {
      LightDesc d;
      d.type = LightType::Directional;
      d.real = true;
      d.direction = glm::vec3(-dir);
      set_rgb(d, e);
      lighting_.lights.push_back(d);
      const ShRgb sh = sh_directional_light(dir, e);
      lighting_.light_sh.push_back(sh);
      lighting_.foldable.push_back(1);
      for (int i = 0; i < kMaxShCoeffs; ++i) ambient[size_t(i)] -= sh[size_t(i)];
    }
  }
  lighting_.ambient_real = with_near_field(ambient);
  lighting_.ambient_virtual = ShRgb{};
  lighting_.ambient_regions.clear();
  lighting_.estimate = est;
  if (near) add_near_field(lighting_.estimate, l);
  ++lighting_.revision;
}

void LightStage::add_near_field(LightEstimate& estimate, const ShRgb& distant) const {
  // The exported SH is all the light reaching the focus (light_at_point); its dominant light
  // stays the distant light's (the near field is many dim sources, none of them the main light).
  const auto direction = estimate.direction_to_light;
  const auto intensity = estimate.dominant_intensity;
  ShRgb sources{};
  for (int i = 0; i < kMaxShCoeffs; ++i) {
    const auto& c = estimate.sh_radiance[size_t(i)];
    sources[size_t(i)] = glm::dvec3(c[0], c[1], c[2]);
  }
  fill_light_estimate(light_at_point(sources, distant, near_field_, near_hidden_), estimate.bands, estimate);
  estimate.direction_to_light = direction;
  estimate.dominant_intensity = intensity;
}

void LightStage::set_residual_lighting() {
  // The estimate's first `residual_shading_bands` bands; the mean radiance (band 0) at least
  // 0: light cannot be negative, and a mean below 0 says the lamps' model already sends more
  // than the camera saw (its shadows outside the view are not modelled), not that light is
  // missing.
  const ShRgb& l = estimator_->filtered();
  const int kept = settings_.residual_shading_bands * settings_.residual_shading_bands;
  for (int i = 0; i < kMaxShCoeffs; ++i)
    lighting_.ambient_real[size_t(i)] = i < kept ? l[size_t(i)] : glm::dvec3(0.0);
  lighting_.ambient_real[0] = glm::max(lighting_.ambient_real[0], glm::dvec3(0.0));
  lighting_.ambient_is_residual = true;
  lighting_.ambient_holds_real_bounce = true;
  finish_declared();
}

void LightStage::use_external_system() {
  external_system_ = true;
  // Checked in create(): cannot fail here.
  estimator_.emplace(std::move(*LightEstimator::create(settings_.external_estimator)));
  planned_ = LightSourceKind::Probeless;
  lighting_.source = planned_;
  lighting_.environment = false;
  max_lights_ = 1;
  probeless_.reset();
  samples_.reset();
  lamp_fitter_.reset();
  albedo_fitter_.reset();
  albedo_fits_ = 0;
  albedo_store_size_ = 0;
  albedo_urgent_in_ = -1;
  lamp_search_due_ = false;
  near_field_on_ = near_field_valid_ = false;
  lamp_ = PointLampFit{};
  residual_ = false;
  set_probeless_lighting();
}

Status LightStage::submit_system(const LightSystem& system, int64_t frame_index, double timestamp_s,
                                 int solve_bands, std::vector<std::string>& notes) {
  auto r = estimator_->update(system, frame_index, timestamp_s, solve_bands);
  if (!r) {
    notes.push_back("light: " + r.error().message);
    return ok_status();  // the estimate keeps its last value: a broken frame is not fatal
  }
  if (planned_ == LightSourceKind::Probeless) set_probeless_lighting();
  return ok_status();
}

void LightStage::update_albedo(const RadianceSamples& store, bool first) {
  // A fit is spread over frames, a step each. After a light change the receivers are wanted
  // soon (the lamp search waits for them): once the view's parts are all in the store again
  // (`parts` frames on), a fit in bigger steps (three frames, not eight), and the lamp is
  // searched as soon as it is in.
  const bool urgent = albedo_urgent_in_ == 0;
  if (albedo_urgent_in_ > 0 && --albedo_urgent_in_ == 0) albedo_fitter_->restart();
  if (!first && albedo_urgent_in_ <= 0) {
    if (!albedo_fitter_->busy()) albedo_fitter_->begin(store);
    const int count = urgent ? (albedo_fitter_->settings().receivers + 1) / 2 : 0;
    if (albedo_fitter_->busy() && albedo_fitter_->step(count)) {
      lamp_search_due_ = urgent;
      albedo_urgent_in_ = -1;
      // The first fit under a new light (and the lamp search right after it) changes what the
      // rows hold: the next solve replaces the estimate too, rather than being filtered towards
      // from one solved while the receivers still held the old light (measured: a lamp switched on
      // in a white corner overshot by a third and took 39 frames to settle).
      if (urgent) estimator_->restart_filter(1);
      const AlbedoFit fit = albedo_fitter_->solve(lamp_.found ? &lamp_ : nullptr);
      // A running mean over the fits (at most the last kAlbedoFits). The albedo is the
      // surfaces', not the light's: after the first kAlbedoSettleFits it moves only when the
      // store has grown by kAlbedoGrowth since it last moved (new surfaces seen), so a still
      // camera's estimate settles, and a light switched on is not also read as new albedo (the
      // bounce's share changes with the light: measured, followed after 23-71 frames instead of
      // 7-31 while every fit moved it).
      const size_t seen = store.size();
      if (fit.found && (albedo_fits_ < kAlbedoSettleFits || double(seen) >= kAlbedoGrowth * double(albedo_store_size_))) {
        albedo_fits_ = std::min(albedo_fits_ + 1, kAlbedoFits);
        albedo_store_size_ = std::max(albedo_store_size_, seen);
        estimator_->set_albedo(estimator_->albedo() + (fit.albedo - estimator_->albedo()) / double(albedo_fits_));
      }
      if (near_field_on_) near_field_valid_ = albedo_fitter_->near_field_at(glm::dvec3(settings_.focus), store, near_field_, &near_hidden_);
    }
  }
}

void LightStage::search_lamp(const RadianceSamples& store, const glm::dvec3& albedo) {
  lamp_search_due_ = false;
  // With the albedo fit's receivers the lamp is fitted to the light it gives directly: their
  // colour with the light bounced onto them taken off. Right after a light change they are
  // being fitted again (their colours were the old light's): the search waits for them, rather
  // than reading the store's samples with the bounce in once and then jumping to where the
  // direct light puts the lamp.
  const bool direct = albedo_fitter_ && !albedo_fitter_->fitted().empty();
  if (albedo_fitter_ && !direct && albedo_fits_ > 0) return;
  if (direct) {
    direct_samples_.clear();
    for (const AlbedoFitter::Receiver& r : albedo_fitter_->fitted())
      direct_samples_.push_back({r.p, r.n, glm::max(r.c - albedo * r.bounce, glm::dvec3(0.0))});
  }
  const PointLampFit fit = direct ? lamp_fitter_->fit(direct_samples_, albedo) : lamp_fitter_->fit(store, albedo);
  // Fits of the same lamp are averaged (a fit reads a few hundred samples, so its position
  // scatters by a decimetre or two from one to the next); another lamp, or none, replaces it.
  if (fit.found && lamp_.found && glm::distance(fit.position, lamp_.position) < kSameLampM) {
    lamp_.position += kLampSmoothing * (fit.position - lamp_.position);
    lamp_.intensity += kLampSmoothing * (fit.intensity - lamp_.intensity);
    return;
  }
  // Hysteresis: a lamp found stays while a point still explains the samples clearly better
  // than a distant light, if no longer by the margin it took to find it (a still view's fit
  // hovers at that margin: the lamp came and went every few fits).
  if (!fit.found && lamp_.found && fit.residual_point <= kKeepLampResidual * fit.residual_distant) return;
  lamp_ = fit;
}

Status LightStage::add_probeless_parts(const frame::CameraView& camera, std::vector<std::string>& notes,
                                       bool& solved) {
  solved = false;
  if (camera.empty()) {
    // The first frames_in_flight frames of a lagged view (frame/camera_view.h).
    notes.push_back("light: no camera frame readable on the host yet (frames on the device are read "
                    "frames_in_flight frames later): the estimate waits");
    return ok_status();
  }
  // Rows interleaved over `parts` frames; until the first estimate exists the whole system is
  // built at once, so no frame is lit by the prior.
  const int parts = probeless_->settings().parts;
  const bool first = !estimator_->estimate().valid;
  RadianceSamples* store = samples_ ? &*samples_ : nullptr;
  for (int p = first ? 0 : next_part_; p < (first ? parts : next_part_ + 1); ++p)
    MRGI_TRY(probeless_->add_part(camera, cameras_.exposure, p, pending_, store));
  if (store && store->end_frame(camera.index)) {
    // The light changed (a lamp switched on or off): the samples out of view are gone and the
    // next two solves (by then this view's parts are all in, at most 2 x `parts` frames on; no
    // frame pays for a whole grid) replace the estimate instead of being filtered towards from
    // the old light.
    estimator_->restart_filter(2);
    if (albedo_fitter_) {
      albedo_fitter_->restart();
      albedo_urgent_in_ = parts;
      near_field_valid_ = false;  // the old light's bounce, until the next fit
    }
    notes.push_back("light: the light changed (surfaces seen again differ in brightness): the probeless "
                    "estimate restarts from the views after it");
  }
  if (store && albedo_fitter_) update_albedo(*store, first);
  const glm::dvec3 albedo = estimator_->albedo();
  // The near lamp is looked for half way through the parts, not with the solve, so no frame
  // pays for both (each about 2 ms of one core at 640x480).
  if (store && lamp_fitter_ && (first || next_part_ == parts / 2 || lamp_search_due_)) search_lamp(*store, albedo);
  next_part_ = first ? 0 : (next_part_ + 1) % parts;
  solved = next_part_ == 0;
  if (solved) {
    if (store) {
      pending_.clear();
      // With the near field on, the distant light is solved from each sample's colour less the
      // bounce its nearest fitted receiver (same side, within 0.5 m) receives.
      const std::vector<AlbedoFitter::Receiver>* fitted = albedo_fitter_ ? &albedo_fitter_->fitted() : nullptr;
      const std::function<glm::dvec3(const glm::vec3&, const glm::vec3&)> bounce = [&](const glm::vec3& p, const glm::vec3& n) {
        double best = 0.25;
        glm::dvec3 out(0.0);
        for (const AlbedoFitter::Receiver& r : *fitted) {
          const glm::dvec3 v = r.p - glm::dvec3(p);
          const double d2 = glm::dot(v, v);
          if (d2 < best && glm::dot(r.n, glm::dvec3(n)) > 0.7 * glm::length(glm::dvec3(n))) {
            best = d2;
            out = albedo * r.bounce;
          }
        }
        return out;
      };
      const bool direct_rows = near_field_on_ && near_field_valid_ && fitted && !fitted->empty();
      const glm::dvec3 floor = estimator_->dominant_normal();
      store->add_to(pending_, &estimator_->filtered(), albedo, lamp_.found ? &lamp_.position : nullptr,
                    lamp_.found ? &lamp_.intensity : nullptr, direct_rows ? &bounce : nullptr,
                    glm::length(floor) > 0.5 ? &floor : nullptr);
    }
    auto r = estimator_->update(pending_, camera.index, camera.timestamp);
    if (!r) notes.push_back("light: " + r.error().message);
    pending_.clear();
  }
  return ok_status();
}

Status LightStage::update(const frame::CameraView& camera, std::vector<std::string>& notes) {
  char text[200];
  const EnvironmentDesc& env = scene_.environment;
  if (planned_ == LightSourceKind::Environment && env.from_env_camera) {
    if (camera.env && cameras_.env_camera) {
      // Declared lamps the env camera sees are taken out of its image first (lamp_removal.h).
      const ImageRGBF* image = camera.env;
      lamps_removed_ = 0;
      if (settings_.remove_declared_lamps && !real_lamps_.empty()) {
        env_scratch_ = *camera.env;
        lamps_removed_ = lamp_removal_.apply(env_scratch_, *cameras_.env_camera, real_lamps_);
        if (lamps_removed_ > 0) image = &env_scratch_;
      }
      MRGI_TRY(env_->update(*image, *cameras_.env_camera, glm::dquat(env.rotation), env.intensity,
                            settings_.unseen_from_camera ? mean_camera_radiance(camera) : glm::dvec3(0.0)));
    } else if (camera.env) {
      notes.push_back("light: this frame's env image came without an env camera model (capture.json "
                      "env_camera): not used");
    } else if (env_->valid()) {
      notes.push_back("light: no env image in this frame, the last one's light kept");
    }
    if (env_->valid()) {
      mark_near_regions(camera);
      set_environment_lighting(env.real);
      lighting_.source = LightSourceKind::Environment;
      lighting_.ambient_holds_real_bounce = settings_.unseen_from_camera && cameras_.env_camera.has_value();
      lighting_.ambient_below_from_camera = lighting_.ambient_holds_real_bounce;
    } else {
      // No environment image yet: the lamps alone (or nothing).
      lighting_.lights.resize(size_t(declared_));
      lighting_.light_sh.resize(size_t(declared_));
      lighting_.foldable.resize(size_t(declared_));
      lighting_.ambient_real = lighting_.ambient_virtual = ShRgb{};
      lighting_.ambient_regions.clear();
      lighting_.source = declared_ > 0 ? LightSourceKind::Declared : LightSourceKind::None;
      finish_declared();
    }
  }
  if (planned_ == LightSourceKind::Probeless && !external_system_) {
    bool solved = false;
    MRGI_TRY(add_probeless_parts(camera, notes, solved));
    if (solved) set_probeless_lighting();
  }
  if (residual_) {
    bool solved = false;
    MRGI_TRY(add_probeless_parts(camera, notes, solved));
    if (solved) {
      set_residual_lighting();
      finish_declared();
    }
  }
  lighting_.estimate.frame_index = planned_ == LightSourceKind::Probeless ? lighting_.estimate.frame_index : camera.frame_index;
  lighting_.estimate.timestamp = planned_ == LightSourceKind::Probeless ? lighting_.estimate.timestamp : camera.frame_timestamp;

  switch (lighting_.source) {
    case LightSourceKind::Probeless: {
      const LightEstimate& e = lighting_.estimate;
      std::snprintf(text, sizeof text,
                    "light: probeless estimate from %s (frame %lld, confidence %.2f)%s",
                    external_system_ ? "the technique's transfer" : "colour and depth",
                    static_cast<long long>(e.frame_index), double(e.confidence),
                    e.valid ? "" : "; none solved yet: lit by the prior (uniform grey light)");
      break;
    }
    case LightSourceKind::Environment:
      std::snprintf(text, sizeof text, "light: environment image (%s, %zu median-cut regions, %d shadowed%s%s)%s",
                    env.from_env_camera ? "env camera" : "file", env_->lights().size(),
                    int(lighting_.lights.size()) - declared_,
                    std::count(near_.begin(), near_.end(), uint8_t(1)) > 0 ? ", bright near surfaces left as ambient" : "",
                    lamps_removed_ > 0 ? (lamps_removed_ == 1 ? ", 1 declared lamp taken out of it"
                                                              : ", declared lamps taken out of it")
                                       : "",
                    declared_ > 0 ? " and declared lamps" : "");
      break;
    case LightSourceKind::Declared:
      std::snprintf(text, sizeof text, "light: %d declared lamp(s) (scene.json)%s", declared_,
                    residual_ ? " and the residual light estimated from colour and depth" : "");
      break;
    case LightSourceKind::None:
      std::snprintf(text, sizeof text, "light: NONE: no lamp, no environment image yet and no estimate: "
                                       "the virtual objects are unlit");
      break;
  }
  notes.push_back(text);
  return ok_status();
}

}  // namespace mrgi::light
