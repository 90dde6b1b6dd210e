// The light-estimation family (perf/suite/light/family.json): every capture replayed
// twice through one technique, once lit by what its scene.json declares (lamps, environment
// image: the true light) and once with nothing declared (the runtime's probeless estimate), and
// the estimate compared with the truth, the light sources as the virtual objects' centre sees
// them (light_probe/probe_direct.exr, `mrgi synth`: environment and lamps where no real surface
// blocks them; the estimate is of the real lights, so bounce light is not part of the truth):
//   direction error   degrees between the dominant directions (band 1 of the SH)
//   irradiance error  RMS over 64 normals spread over the sphere of |E_est(n) - E_true(n)|
//                     (luminance) over the RMS of E_true(n), against the path-traced probe
//                     (probe.exr: bounce light included, as it lights the object): 0 = the same
//                     shading of a diffuse surface of any orientation
//   colour error      the largest relative difference of a channel of band 0 (the mean light),
//                     each normalised by its luminance: 0.1 = within 10 % per channel
//   RDE ratio         pooled RDE lit by the estimate over pooled RDE lit by the truth
// Figures are taken from the last frame's estimate (the filter has seen every frame).
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <optional>

#include "mrgi/expected.h"
#include "mrgi/light_estimate.h"
#include "mrgi/metrics.h"
#include "mrgi/platform/capture.h"
#include "mrgi/scene.h"

namespace mrgi::perf {

struct LightFamilyScene {
  std::string name, capture, varies;
  bool held_out = false;
};

// BadInput naming the file and field for a manifest that breaks its format.
Expected<std::vector<LightFamilyScene>> load_light_family(const std::string& manifest_path);

struct LightFamilyResult {
  LightFamilyScene scene;
  std::string estimate_source;   // the note the estimate-lit run gave for its light
  double direction_error_deg = 0.0;
  double irradiance_error = 0.0;
  double colour_error = 0.0;
  double confidence = 0.0;
  std::array<float, 3> estimate_direction{}, truth_direction{};  // towards the dominant light
  std::array<float, 3> estimate_mean{}, truth_mean{};            // band-0 radiance, linear RGB
  std::array<float, 3> truth_all_mean{};  // band 0 of everything reaching the objects (probe.exr, bounce included)
  double rde_true = 0.0, rde_estimate = 0.0;  // pooled over the frames, all pixels
  double rde_ratio() const { return rde_true > 0.0 ? rde_estimate / rde_true : 0.0; }
  bool sky = false;              // lit by a procedural sun and sky (colour target applies)
};

struct LightFamilySettings {
  std::string manifest = "perf/suite/light/family.json";
  std::string technique = "baseline";
  int level = 0;
  std::string root = ".";        // captures' paths are relative to this
  bool validate = false;
  // Which scenes run: "all", "tuning" (the half a parameter may be chosen on) or "held-out".
  std::string half = "all";
  bool accumulate_views = true;  // RuntimeSettings::light_accumulate_views
  bool near_lamps = true;        // RuntimeSettings::light_near_lamps
  bool albedo_fit = true;        // RuntimeSettings::light_albedo_fit
  bool near_field = true;        // RuntimeSettings::light_near_field
  bool distant_views = true;     // RuntimeSettings::light_distant_views
};

// One capture replayed through the runtime: the error of every frame and the light it came
// back with (with frames in flight, the newest estimate when that frame was collected).
struct LightReplayFrame {
  double rde = 0.0;                   // all pixels
  std::optional<LightEstimate> light;
};
struct LightReplay {
  RdeReport pooled;
  bool any = false;
  std::optional<LightEstimate> light;  // the last frame's
  std::string light_note;
  std::vector<LightReplayFrame> frames;
  int changes = 0;  // frames whose notes say the light stage detected a change of the light
};
Expected<LightReplay> replay_light_capture(const CaptureReader& capture, const SceneDesc& scene,
                                           const LightFamilySettings& settings);
// A capture's light probe as an estimate: `direct` the light sources only (probe_direct.exr),
// else everything reaching the virtual objects' centre (probe.exr).
Expected<LightEstimate> load_light_truth(const std::string& capture_dir, bool direct);
double family_irradiance_error(const LightEstimate& estimate, const LightEstimate& truth);
double family_colour_error(const LightEstimate& estimate, const LightEstimate& truth);

// Runs every scene (progress through `progress(name, done, total)` when given).
Expected<std::vector<LightFamilyResult>> run_light_family(
    const LightFamilySettings& settings,
    const std::function<void(const std::string&, size_t, size_t)>& progress = {});

// Markdown: one row per scene, then the summary of each half (median and worst direction
// error, median irradiance error, worst colour error on the sky scenes, median and worst RDE
// ratio) against the family's targets (direction median / worst 15 / 30 degrees, colour worst
// 0.10 on the sky scenes, RDE ratio median / worst 1.15).
std::string light_family_markdown(const std::vector<LightFamilyResult>& results,
                                  const LightFamilySettings& settings);
std::string light_family_json(const std::vector<LightFamilyResult>& results);

}  // namespace mrgi::perf
