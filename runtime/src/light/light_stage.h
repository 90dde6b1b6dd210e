// The light stage (docs/DESIGN.md "estimate light"): between reconstruction and the technique, once
// per frame, it decides from what the capture or sensor gives where the real light comes from
// and hands every technique the same answer:
//   - declared lamps (scene.json `lights`, real and virtual, as tracked lamps are);
//   - an environment image (scene.json `environment`: a file, or the env camera's frames):
//     median-cut importance sampling (env_sampler.h); of the strongest regions, those that are
//     compact, bright and distant (LightStageSettings::shadowed_min_contrast, near_field_
//     distance_m) become shadowed directional lights, the rest stays as SH ambient (which the
//     direct-light block occludes by the virtual objects, shading/environment_occlusion.h).
//     Declared lamps the env camera sees are taken out of its images first (lamp_removal.h);
//     what it cannot see (below an upward fisheye) takes the colour camera's mean radiance;
//   - neither: the probeless estimate from colour and depth (light::LightEstimator, fed by the
//     stage's own ProbelessBuilder or by a technique's GPU sums, ssrt's), as one shadowed
//     dominant directional light plus the rest of the estimate as SH ambient. The stage's own
//     estimate keeps what every view showed (radiance_samples.h), so it grows with the views a
//     user sweeps; the surfaces' albedo, which scales the whole estimate, is measured from the
//     light they bounce onto each other (albedo_fit.h) instead of assumed grey (0.5), and that
//     bounce, computed from the surfaces seen, reaches the virtual objects as ambient (the near
//     field) instead of being read as distant light; and where
//     those views show a near lamp (point_lamp_fit.h, fitted to the light with that bounce
//     taken off) the shadowed light is that lamp at its position instead of a distant one;
//   - lamps without an environment also get the residual: the light the camera sees that the
//     lamps' direct light does not explain (the room's own interreflection, daylight through a
//     window), estimated probelessly from the same rows with the lamps' light taken off each
//     (ProbelessBuilder::set_known_lamps), as SH ambient (LightStageSettings::residual_light).
// Declared lamps and an environment add up (a desk lamp in a sunlit room). Each frame's stats
// carry a note naming the source; a frame lit by nothing says so.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "frame/camera_view.h"
#include "light/albedo_fit.h"
#include "light/env_sampler.h"
#include "light/lamp_removal.h"
#include "light/point_lamp_fit.h"
#include "light/probeless.h"
#include "light/sh_estimator.h"
#include "light/sh_tools.h"
#include "mrgi/light_estimate.h"
#include "mrgi/runtime.h"
#include "mrgi/scene.h"

namespace mrgi::light {

// The most lights a frame's Lighting holds (MRGI_MAX_LIGHTS of shaders/common/light_set.glsl).
inline constexpr int kMaxStageLights = 8;

enum class LightSourceKind { None, Declared, Environment, Probeless };
const char* source_name(LightSourceKind kind);

struct LightStageSettings {
  EnvSamplerSettings environment;
  // Regions of the environment's cut that become shadowed directional lights (the strongest;
  // the others' light stays in the ambient SH, unshadowed). 0..8, at most 8 minus the lamps.
  int shadowed_environment_lights = 4;
  // Which regions may become shadowed lights at all: only compact, bright ones (a sun, a
  // window, an undeclared lamp), whose light arrives from one narrow direction, so one shadow
  // map stands for it. A region qualifies when its mean radiance (luminance over its lit cells)
  // is at least shadowed_min_contrast times the environment's mean over all its lit cells AND
  // its brightest cell belongs to a source (a connected group of cells at least
  // EnvSamplerSettings::source_contrast times that mean) of at most shadowed_max_solid_angle_sr:
  // the source's size, not the region's (a median cut splits a big bright wall into small
  // regions, each of which would look compact). Everything else (a sky, a room's
  // walls and ceiling, a lit wall close to the env camera, which a median cut splits into broad
  // regions of ordinary radiance) stays in the ambient SH, which the direct-light block occludes
  // softly by the virtual objects (shading/environment_occlusion.h) instead of casting a few
  // long hard shadows from it. 0.05 sr: a cone of 7.2 degrees half-angle (a window 0.5 m across
  // seen from 2 m); contrast 3: a sun or window is tens to thousands of times the mean, an overcast sky's
  // or a room's brightest broad parts 1-2 times.
  double shadowed_min_contrast = 3.0;
  double shadowed_max_solid_angle_sr = 0.05;
  // Of the regions left in the ambient, those whose mean radiance is at least this many times
  // the environment's mean are also kept as cones for the virtual objects' occlusion
  // (Lighting::ambient_regions): a region brighter than the mean is where the objects' soft
  // shadow points; at or below it, the SH's blur loses little. >= 0.
  double occlusion_region_min_contrast = 1.0;
  // The cones come from the environment's light sources (EnvSamplerSettings::source_contrast:
  // connected cells at least that many times the mean radiance), each gathered whole, strongest
  // first, instead of from the median cut's regions: a median cut splits an extended bright
  // source (a sunlit wall, a window, a hazy low sun) into pieces joined with broad dim parts
  // around it, and the pieces that pass the contrast rule are the small ones, so the objects'
  // soft shadow pointed at whatever small bright regions the sky had. false: the regions.
  bool occlusion_regions_from_sources = true;
  // What an env camera cannot see (below an upward fisheye's horizon: the floor and the room
  // around the virtual objects) lights them as the mean radiance the colour camera sees, not as
  // darkness. Why: the light from below is what the real surfaces reflect, and the camera
  // frame shows those surfaces; with none, a virtual object's underside and lower half were
  // black where the truth is lit by the floor.
  bool unseen_from_camera = true;
  // Declared real lamps the env camera sees are taken out of its images before sampling
  // (light/lamp_removal.h), so their light is not counted twice (as the lamp and as an
  // environment region).
  bool remove_declared_lamps = true;
  // Near field: a region whose direction, from the env camera's position (capture.json
  // env_camera.position), reaches a surface of the frame's depth image within this distance is
  // a nearby surface the env camera sees (a lit table top, a wall a few decimetres away), whose
  // light is bounce, not a distant light: it never becomes a shadowed light, whatever its
  // contrast. The ray is marched in near_field_step_m steps; it meets a surface where a step
  // lies behind the depth image's surface (by more than near_field_tolerance_m) after one in
  // front of it. Directions the depth camera does not see count as distant. 3 m: a room.
  double near_field_distance_m = 3.0;
  double near_field_step_m = 0.02;
  double near_field_tolerance_m = 0.03;
  LampRemovalSettings lamp_removal;
  ProbelessSettings probeless;
  // The probeless source's memory of the views seen (radiance_samples.h): the system is solved
  // over every surface the camera has swept, not only the current view. The residual estimate
  // (declared lamps) stays per view: its low-order ambient is constrained by one view.
  RadianceSampleSettings samples;
  // A near lamp found from those views (point_lamp_fit.h): lit as a shadowed point light at its
  // position, the SH estimate then holding the rest.
  PointLampFitSettings point_lamp;
  // The real surfaces' albedo from their interreflection among those views (albedo_fit.h),
  // instead of the estimator's grey world.
  AlbedoFitSettings albedo_fit;
  // With the albedo fit: the distant light is solved from the samples with the bounce they
  // receive taken off, and the light the kept surfaces send to the virtual objects' centre (the
  // near field, AlbedoFitter::near_field_at) is added to the ambient. Why: a white corner's
  // interreflection, strongest at its walls and crease, read as distant light was 1.4x what
  // reaches the box (RDE ratio on the moving family's tuning half 1.42 / 1.94 -> 1.33 / 1.54).
  // The exported estimate is then the light reaching the virtual objects' centre: the near field
  // plus the distant light from the directions no seen surface covers (as an app lights its
  // object with it, and as ARCore's environment estimate holds the room around the anchor).
  bool near_field = true;
  // The estimator of the probeless source fed by the stage's own builder. RGB (white_light
  // false): the paper's white-light assumption gives a grey estimate under a blue sky. Chosen on
  // the light family's tuning half only (perf/suite/light/family.json; perf/results/
  // light-family/light-family.md), direction error median / worst over its six scenes:
  //   as ssrt's (regularisation 1e-2, no non-negativity)              20.6 / 37.8 degrees
  //   + non-negative radiance (nonnegative_penalty 10)                18.4 / 38.0
  //   + regularisation 1e-3                                           17.4 / 40.5 (chosen)
  //   (+ the light's colour by vote, ProbelessSettings::grey_vote: 12.3 / 39.6, but worse on
  //   the held-out half, so off: see there)
  //   (3 bands: 15.0 / 49.5; 128 directions: 19.2 / 35.5 at twice the cost; balancing the
  //   samples' orientations (ProbelessSettings::balance_normals): 24.0 / 46.6; below-surface
  //   weight 1: 15.8 / 42.5)
  LightEstimatorSettings estimator = [] {
    LightEstimatorSettings s;
    s.white_light = false;
    s.nonnegative_penalty = 10.0;
    s.relative_regularisation = 1e-3;
    return s;
  }();
  // The estimator when a technique hands in its own sums (ssrt: its transfer's visibility and
  // every pixel; the settings it was tuned with), in RGB.
  LightEstimatorSettings external_estimator = [] {
    LightEstimatorSettings s;
    s.white_light = false;
    return s;
  }();
  // With declared lamps and no environment: estimate the residual light (above) and hand it to
  // the techniques as ambient_real. Why: the differential composite scales a real pixel's change
  // by the camera's value over the model's L_r (compose.comp), and without the room's own light
  // L_r holds only what the lamps send directly (plus a technique's few modelled bounces):
  // where the lamps barely reach, a virtual object's small bounce became a large relative
  // change, and virtual surfaces missed the room's light altogether. Measured (perf/results/
  // residual-light.md), RDE all / real / virtual at dir high: corner 0.655 / 1.036 / 0.636 ->
  // 0.298 / 0.930 / 0.244; on two held-out scenes (perf/heldout/) 0.579 -> 0.350 and 0.194 ->
  // 0.160. The residual is unshadowed ambient, the same in L_r and L_rv (it cancels in the
  // delta; a virtual object blocking it is not modelled). It holds the real scene's bounce, so
  // where a technique already carries that bounce to virtual surfaces through a volume (dlpv's
  // V^rho) it is left off virtual pixels (Lighting::ambient_is_residual; measured: with both,
  // dlpv high's virtual RDE on corner 0.432 -> 0.714). dir's VPLs carry some of it too, from
  // the real surfaces in the influence sphere only, and with the residual on its virtual pixels
  // every lamp scene measured improved: the double count there is the smaller error.
  bool residual_light = true;
  // The residual's sampling: half the probeless source's grid (a low-order ambient needs fewer
  // samples; a quarter of the cost, about 0.6 ms a frame at 640x480 spread over 8 frames).
  ProbelessSettings residual_probeless = [] {
    ProbelessSettings s;
    s.grid_width = 40;
    return s;
  }();
  // The residual's estimator: the probeless one's, but with the paper's white light (Sec. 5:
  // the channels solved as one). Why: with a gray-world albedo per channel, a coloured wall
  // becomes coloured light, and the lamps' light taken off first leaves the walls' colour as
  // most of what is left.
  LightEstimatorSettings residual_estimator = [] {
    LightEstimatorSettings s;
    s.white_light = true;
    s.nonnegative_penalty = 10.0;
    s.relative_regularisation = 1e-3;
    return s;
  }();
  // Bands of the residual estimate the techniques are lit with (1..3; the fit always solves
  // the estimator's bands, 4, so the directional part of the residual does not bias its mean:
  // a view of mostly floor lit from above would read a band-0-only fit's mean too high).
  // 1, the mean radiance only. Why: the directional bands are where the error of the lamps'
  // model lands (their shadows and spot profile outside the view, which the subtraction cannot
  // see), and a view's two or three surface orientations constrain them poorly. Measured at
  // dir / baseline high, RDE all (corner; desk_spot): none 0.655 / 0.709 (0.135 / 0.192);
  // 4 bands kept 0.720 / 0.755 (0.117 / 0.155); 1 band kept 0.298 / 0.340 (0.123 / 0.172);
  // a band-0-only fit 0.283 / 0.306 (0.135 / 0.192: its mean is below 0 on desk_spot, clamped).
  int residual_shading_bands = 1;
  // Where declared lamps are seen from for the exported estimate (LightEstimate: SH and
  // dominant light of the lamps at this point, world metres): the virtual objects' centre.
  glm::vec3 focus{0.0f};
};

// One frame's light, as every technique reads it.
struct Lighting {
  LightSourceKind source = LightSourceKind::None;
  bool environment = false;          // an environment contributes (with lamps or alone)
  // Lights with shadows: declared lamps, then environment regions or the probeless dominant
  // light (directional, `real`). Capacity kMaxStageLights, reserved at start-up.
  std::vector<LightDesc> lights;
  // Per light: the radiance SH of the light it stands for (an environment region's own cells,
  // the probeless dominant light's delta) and whether it may be folded back into the ambient:
  // a technique that shades fewer shadowed lights (a cheaper level) adds the SH of those it
  // drops to ambient_real (or ambient_virtual for a virtual environment). Declared lamps are
  // not foldable (a point lamp is no distant light).
  std::vector<ShRgb> light_sh;
  std::vector<uint8_t> foldable;
  // Radiance SH (4 bands) of the light not in `lights`: real (lights real and virtual surfaces)
  // and virtual (a virtual environment: lights virtual surfaces only).
  ShRgb ambient_real{}, ambient_virtual{};
  // The bright parts of the ambient's environment, kept as cones for the virtual objects'
  // occlusion of it (shading/environment_occlusion.h: their shadows fall in their direction,
  // which the SH blurs): the environment's light sources (EnvSource: connected cells brighter
  // than EnvSamplerSettings::source_contrast x the mean), each whole but for the regions drawn
  // as lights, whose mean radiance is at least LightStageSettings::occlusion_region_min_contrast
  // x the environment's, strongest first, at most kMaxOcclusionRegions (with
  // occlusion_regions_from_sources false: the median cut's regions not drawn as lights, most
  // concentrated first). Their light stays in the ambient SH too
  // (`sh` is its part). Empty without an environment.
  struct AmbientRegion {
    glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, world, towards the region
    glm::dvec3 irradiance{0.0};           // W/m^2 per linear RGB channel at normal incidence
    double half_angle_rad = 0.0;          // of the cone of the region's solid angle
    ShRgb sh{};                           // the region's radiance SH (EnvLight::region_sh)
  };
  static constexpr int kMaxOcclusionRegions = 4;
  std::vector<AmbientRegion> ambient_regions;
  // ambient_real is the residual estimate (LightStageSettings::residual_light): all of the
  // real light but the lamps' direct light, the real scene's own bounce included.
  bool ambient_is_residual = false;
  // The ambient already holds the real scene's own bounce: the residual estimate, an env
  // camera's image whose unseen lower hemisphere is the colour camera's mean radiance
  // (LightStageSettings::unseen_from_camera), the probeless estimate (fitted to what the camera
  // sees); not an environment image file's ambient, which knows nothing of the real surfaces
  // round the objects. (A technique's own bounce volume would count that bounce twice:
  // technique/dlpv/dlpv.h rho_beside_bounce_ambient.)
  bool ambient_holds_real_bounce = false;
  // Of those, an env camera's image whose unseen lower hemisphere is the colour camera's mean
  // radiance (LightStageSettings::unseen_from_camera): the real surfaces' light, local bounce
  // included, is the ambient's light from below (technique/dir/dir.h
  // real_bounce_beside_camera_ambient).
  bool ambient_below_from_camera = false;
  // Every real light as an estimate (SH, dominant light, confidence), the public form.
  LightEstimate estimate;
  // Bumped whenever `lights` changed (shadow maps are re-planned on a change only).
  uint64_t revision = 0;
};

class LightStage {
 public:
  // BadUsage for settings out of range; BadInput (naming the file) for an environment image
  // that cannot be read.
  static Expected<std::unique_ptr<LightStage>> create(const LightStageSettings& settings,
                                                      const SceneDesc& scene, const CameraSetup& cameras);

  // A technique that sums its own probeless system on the GPU (ssrt) calls this at start-up:
  // the stage then never runs its own builder, submit_system() feeds the estimator, and the
  // source is the probeless estimate whatever the scene declares (ssrt's paper estimates the
  // light from the frames; it has no use for lamps or an environment image).
  void use_external_system();
  bool external_system() const { return external_system_; }

  // This frame's light from the camera as the host sees it (frame/camera_view.h: this frame's
  // images, or an earlier frame's at its own pose; an empty view adds nothing from the camera)
  // and this frame's environment image. `notes` gets one line naming the source (and any
  // problem).
  Status update(const frame::CameraView& camera, std::vector<std::string>& notes);
  // A technique's GPU-summed system (use_external_system), solved into the probeless estimate.
  Status submit_system(const LightSystem& system, int64_t frame_index, double timestamp_s,
                       int solve_bands, std::vector<std::string>& notes);

  const Lighting& lighting() const { return lighting_; }
  // Declared lamp i (scene.json's order) changes from the next update() on: moved, turned,
  // recoloured, dimmed to 0 (off) or back. The number of lamps is the scene's (capacity fixed at
  // start-up: an app that adds lamps later declares them dark). BadUsage naming the field for an
  // index out of range or a lamp scene.json would refuse; a lamp's kind (real or virtual, point,
  // spot or directional) cannot change (its shadow maps were laid out for it).
  Status set_declared_lamp(size_t i, const LightDesc& lamp);
  // Declared lamp i as it is now (the scene's, or the last set_declared_lamp's, normalised).
  const LightDesc& declared_lamp(size_t i) const { return scene_.lights[i]; }
  // Every region of this frame's environment cut (strongest first; empty without an environment
  // or before its first image), for the techniques that light with all of it (dir's environment
  // VPLs); their region_sh add up to the environment's SH. `environment_real()`: scene.json's
  // environment.real.
  const std::vector<EnvLight>& environment_regions() const;
  // Of those, the ones drawn as shadowed lights this frame (indices into environment_regions(),
  // in the order of their lights in Lighting::lights after the declared lamps): not the
  // strongest first few but the compact, bright, distant ones (shadowable_region).
  const std::vector<size_t>& shadowed_environment_regions() const { return shadowed_regions_; }
  bool environment_real() const { return scene_.environment.real; }
  // This frame's filtered environment grid (EnvSampler: world-space equirectangular radiance),
  // nullptr without an environment image or before its first one; for what sees the
  // environment itself (mirrors and glass, specular/). Its width is environment_grid_width().
  const EnvSampler* environment_grid() const {
    return lighting_.environment && env_ && env_->valid() ? &*env_ : nullptr;
  }
  int environment_grid_width() const { return settings_.environment.grid_width; }
  const LightEstimator& estimator() const { return *estimator_; }
  // The probeless source's store of the views seen; null when it does not accumulate.
  const RadianceSamples* radiance_samples() const { return samples_ ? &*samples_ : nullptr; }
  // The largest number of shadowed lights any frame can have (for shadow map allocation).
  int max_lights() const { return max_lights_; }
  LightSourceKind planned_source() const { return planned_; }

 private:
  LightStage() = default;
  void set_probeless_lighting();
  void set_residual_lighting();
  // One step of the albedo fit over the store (albedo_fit.h); a finished fit moves the
  // estimator's albedo.
  void update_albedo(const RadianceSamples& store, bool first);
  // Adds the near field to an exported estimate's SH and takes off the distant light the seen
  // surfaces hide from the focus; its dominant light is kept.
  void add_near_field(LightEstimate& estimate, const ShRgb& distant) const;
  // The near-lamp search (point_lamp_fit.h) over the albedo fit's receivers with their bounce
  // taken off (the store's samples before the first fit); lamp_ follows it.
  void search_lamp(const RadianceSamples& store, const glm::dvec3& albedo);
  // Feeds this frame's part(s) of the stage's own probeless system; `solved` when a whole
  // system was solved this frame.
  Status add_probeless_parts(const frame::CameraView& camera, std::vector<std::string>& notes, bool& solved);
  // `near`: per region of the sampler's cut, whether it is a surface near the env camera
  // (near_regions); empty = none known to be.
  void set_environment_lighting(bool real);
  // Lighting::ambient_regions from this frame's regions and shadowed_regions_.
  void set_ambient_regions();
  // Marks near_ for this frame's regions: the ray from the env camera towards each region's
  // direction crosses a surface of the frame's depth image within near_field_distance_m.
  void mark_near_regions(const frame::CameraView& camera);
  bool crosses_surface(const glm::dvec3& from, const glm::dvec3& direction, const frame::DepthView& depth,
                       const glm::dmat4& world_to_camera) const;
  std::vector<uint8_t> near_;  // per region; reserved at start-up
  // Whether an environment region may be a shadowed light (LightStageSettings::shadowed_min_contrast).
  bool shadowable_region(const EnvLight& r, double mean_luminance) const;
  // The mean radiance of the colour frame (linear, over the exposure): the unseen prior.
  glm::dvec3 mean_camera_radiance(const frame::CameraView& camera) const;
  std::vector<size_t> shadowed_regions_;  // this frame's, indices into the sampler's lights
  std::vector<std::pair<double, size_t>> region_order_;  // set_ambient_regions' (contrast, index)
  std::vector<EnvSource> sources_;        // set_ambient_regions' (occlusion_regions_from_sources)
  LampRemoval lamp_removal_;
  ImageRGBF env_scratch_;                 // the env image with the declared lamps taken out
  int lamps_removed_ = 0;                 // this frame's
  void finish_declared();

  LightStageSettings settings_;
  SceneDesc scene_;
  CameraSetup cameras_;
  LightSourceKind planned_ = LightSourceKind::None;
  int declared_ = 0;                // lamps from scene.json (the first entries of lights)
  int env_lights_ = 0;              // shadowed environment regions
  int max_lights_ = 0;
  bool external_system_ = false;
  bool residual_ = false;           // declared lamps with the residual estimate (residual_light)
  std::optional<EnvSampler> env_;
  bool env_from_file_ = false;
  std::optional<ProbelessBuilder> probeless_;
  std::optional<LightEstimator> estimator_;
  std::optional<RadianceSamples> samples_;  // the probeless source's, when accumulating
  std::optional<PointLampFitter> lamp_fitter_;
  std::optional<AlbedoFitter> albedo_fitter_;
  std::vector<LampFitSample> direct_samples_;  // the lamp fit's input with the bounce off; reserved
  int albedo_fits_ = 0;                        // fits averaged into the estimator's albedo
  bool near_field_on_ = false, near_field_valid_ = false;
  ShRgb near_field_{};
  ShMatrix near_hidden_{};  // the distant light the seen surfaces hide from the focus (albedo_fit.h)
  size_t albedo_store_size_ = 0;               // the store's size when the albedo last moved
  // A light changed: frames until the next albedo fit starts, in two steps (0: under way; -1 none).
  int albedo_urgent_in_ = -1;
  bool lamp_search_due_ = false;               // ... and the lamp searched as soon as it is in
  PointLampFit lamp_;                       // the last solve's
  LightSystem pending_;             // the parts of the probeless system summed so far
  int next_part_ = 0;
  Lighting lighting_;
  ShRgb declared_sh_{};             // the declared real lamps seen from the focus (radiance SH)
  std::vector<LightDesc> real_lamps_;  // the declared real lamps (residual's known light)
  void update_declared_sh();
  std::vector<glm::dvec3> last_env_directions_;
};

// The irradiance of radiance SH `l` (bands 0..2) as one 4x4 matrix per channel, so that
// E_c(n) = (n, 1)^T M_c (n, 1) (Ramamoorthi & Hanrahan 2001, eq. 12): three mat4s a shader
// copies whole and evaluates with two dot products, instead of an array of nine coefficients.
std::array<glm::mat4, 3> irradiance_matrices(const ShRgb& l);

}  // namespace mrgi::light
