// The moving-camera light family (perf/suite/light/moving/family.json): each capture is a
// 90-degree sweep around a virtual object on a table, replayed lit by its true light and by the
// runtime's probeless estimate, with the estimate's figures at every frame (as the sweep grows):
// direction error (degrees, against the light sources as the object's centre sees them),
// colour error (largest per-channel error of the mean light's chromaticity against the light
// sources', light_probe/probe_direct.exr, and against all the light reaching the object's centre,
// probe.exr, bounce included: with the near field the exported SH holds both), confidence, and
// the per-frame RDE ratio (estimate-lit over true-lit, all pixels). After the sweep: the last
// frame's direction and colour, the RDE ratio pooled over the last 8 frames.
//
// Switches: a still camera whose room gets one more lamp at a stated frame (splice_switch.py);
// "followed" is the first frame from which the estimate stays within 10 % in intensity (band 0
// luminance) and 5 degrees in direction of where it ends, counted from the switch.
//
// Drift: one capture played back and forth for N frames; the largest change of the estimate's
// direction (degrees) and intensity (relative) from a tenth of the run on (at least one round
// trip: the store has seen every view and the filter has settled).
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/perf/light_family.h"

namespace mrgi::perf {

struct MovingFrame {
  double direction_error_deg = 0.0, colour_error = 0.0, colour_error_all = 0.0, confidence = 0.0;
  double rde_true = 0.0, rde_estimate = 0.0;
  bool valid = false;  // an estimate existed
};

struct MovingResult {
  LightFamilyScene scene;
  std::vector<MovingFrame> frames;
  double final_direction_deg = 0.0, final_colour = 0.0, final_colour_all = 0.0, final_confidence = 0.0;
  double final_rde_ratio = 0.0;  // pooled over the last 8 frames
  // Band 0 (mean radiance, linear RGB) of the last estimate, of the light sources and of all the
  // light at the objects' centre, so a colour error reads as which channel is off.
  std::array<double, 3> final_band0{}, truth_band0{}, truth_all_band0{};
};

struct SwitchResult {
  std::string name;
  bool held_out = false;
  int switch_frame = 0;
  int followed_after = -1;  // frames after the switch; -1 = never settled
  int changes_noted = 0;    // frames whose notes say a light change was detected
  double final_direction_deg = 0.0;  // against the lamp-on truth
  double intensity_before = 0.0, intensity_after = 0.0;  // band-0 luminance before the switch, at the end
  // Every frame from the switch on that had an estimate: frame, band-0 luminance, direction error
  // against the lamp-on truth (degrees).
  std::vector<std::array<double, 3>> series;
};

struct DriftResult {
  std::string name;
  int frames = 0;
  int settled_from = 0;  // the frame the changes are measured from (a tenth of the run, at least a round trip)
  double direction_deg = 0.0, intensity = 0.0;  // largest change from settled_from on
  // Every 10th frame's estimate: direction (degrees from settled_from's) and intensity (relative).
  std::vector<std::array<double, 3>> series;  // frame, direction_deg, intensity
};

struct MovingFamilyReport {
  std::vector<MovingResult> scenes;
  std::vector<SwitchResult> switches;
  std::vector<DriftResult> drift;
};

struct MovingFamilySettings {
  LightFamilySettings family;     // manifest, technique, level, root, half, accumulate_views
  int drift_frames = 0;           // 0: no drift run
  std::string drift_scene;        // the scene looped (default: the half's first)
  bool switches = true;
};

Expected<MovingFamilyReport> run_moving_family(const MovingFamilySettings& settings,
                                               const std::function<void(const std::string&, size_t, size_t)>& progress = {});
std::string moving_family_markdown(const MovingFamilyReport& report, const MovingFamilySettings& settings);
std::string moving_family_json(const MovingFamilyReport& report);

}  // namespace mrgi::perf
