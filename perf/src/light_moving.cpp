#include "mrgi/perf/light_moving.h"

#include <algorithm>
#include <map>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mrgi/perf/stats.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {
namespace {

namespace fs = std::filesystem;

double band0_luminance(const LightEstimate& e) {
  const mrgi::Rgb& c = e.sh_radiance[0];
  return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

double angle_deg(const std::array<float, 3>& a, const std::array<float, 3>& b) {
  const double la = std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]);
  const double lb = std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]);
  if (!(la > 0.0) || !(lb > 0.0)) return 180.0;
  const double c = (double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2]) / (la * lb);
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

struct Manifest {
  std::vector<LightFamilyScene> scenes;
  struct Switch {
    std::string name, capture;
    bool held_out = false;
  };
  std::vector<Switch> switches;
};

Expected<Manifest> load_moving_manifest(const std::string& path) {
  auto scenes = load_light_family(path);
  if (!scenes) return scenes.error();
  Manifest m;
  m.scenes = *scenes;
  std::ifstream in(path);
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    return fail(ErrorKind::BadInput, path + ": not JSON: " + e.what());
  }
  if (j.contains("switches")) {
    if (!j["switches"].is_array()) return fail(ErrorKind::BadInput, path + ": switches: must be an array");
    for (size_t i = 0; i < j["switches"].size(); ++i) {
      const auto& w = j["switches"][i];
      if (!w.is_object() || !w.contains("name") || !w["name"].is_string() || !w.contains("capture") ||
          !w["capture"].is_string() || !w.contains("held_out") || !w["held_out"].is_boolean())
        return fail(ErrorKind::BadInput, path + ": switches[" + std::to_string(i) +
                                             "]: needs string name and capture, and boolean held_out");
      m.switches.push_back({w["name"], w["capture"], w["held_out"].get<bool>()});
    }
  }
  return m;
}

bool in_half(bool held_out, const std::string& half) { return half == "all" || held_out == (half == "held-out"); }

Expected<CaptureReader> open_rendered(const std::string& dir) {
  if (!fs::exists(fs::path(dir) / "capture.json"))
    return fail(ErrorKind::NotFound, dir + ": not rendered (the moving family's renders are not committed): run "
                                           "bash perf/suite/light/render_moving_family.sh");
  return CaptureReader::open(dir);
}

SceneDesc undeclared(const SceneDesc& truth) {
  SceneDesc s = truth;
  s.lights.clear();
  s.environment = EnvironmentDesc{};
  return s;
}

Expected<MovingResult> run_scene(const LightFamilyScene& sc, const LightFamilySettings& s) {
  const std::string dir = (fs::path(s.root) / sc.capture).string();
  auto capture = open_rendered(dir);
  if (!capture) return capture.error();
  if (!capture->scene() || !capture->has_references())
    return fail(ErrorKind::BadInput, sc.capture + ": a family capture needs scene.json and references");
  auto truth = replay_light_capture(*capture, *capture->scene(), s);
  if (!truth) return fail(truth.error().kind, sc.name + " (true light): " + truth.error().message);
  auto est = replay_light_capture(*capture, undeclared(*capture->scene()), s);
  if (!est) return fail(est.error().kind, sc.name + " (estimate): " + est.error().message);
  auto probe = load_light_truth(dir, true);
  if (!probe) return fail(probe.error().kind, sc.name + ": " + probe.error().message);
  auto all_light = load_light_truth(dir, false);
  if (!all_light) return fail(all_light.error().kind, sc.name + ": " + all_light.error().message);
  MovingResult r;
  r.scene = sc;
  for (size_t i = 0; i < est->frames.size(); ++i) {
    MovingFrame f;
    f.rde_true = truth->frames[i].rde;
    f.rde_estimate = est->frames[i].rde;
    if (const auto& l = est->frames[i].light; l && l->valid) {
      f.valid = true;
      f.direction_error_deg = direction_error_deg(*l, *probe);
      f.colour_error = family_colour_error(*l, *probe);
      f.colour_error_all = family_colour_error(*l, *all_light);
      f.confidence = l->confidence;
    }
    r.frames.push_back(f);
  }
  if (r.frames.empty()) return fail(ErrorKind::BadInput, sc.capture + ": no frames");
  const MovingFrame& last = r.frames.back();
  r.final_direction_deg = last.direction_error_deg;
  r.final_colour = last.colour_error;
  r.final_colour_all = last.colour_error_all;
  r.final_confidence = last.confidence;
  for (int c = 0; c < 3; ++c) {
    r.truth_band0[size_t(c)] = probe->sh_radiance[0][size_t(c)];
    r.truth_all_band0[size_t(c)] = all_light->sh_radiance[0][size_t(c)];
    const auto& l = est->frames.back().light;
    if (l && l->valid) r.final_band0[size_t(c)] = l->sh_radiance[0][size_t(c)];
  }
  double t = 0.0, e = 0.0;
  for (size_t i = r.frames.size() - std::min<size_t>(8, r.frames.size()); i < r.frames.size(); ++i) {
    t += r.frames[i].rde_true;
    e += r.frames[i].rde_estimate;
  }
  r.final_rde_ratio = t > 0.0 ? e / t : 0.0;
  return r;
}

Expected<SwitchResult> run_switch(const Manifest::Switch& w, const LightFamilySettings& s) {
  const std::string dir = (fs::path(s.root) / w.capture).string();
  auto capture = open_rendered(dir);
  if (!capture) return capture.error();
  if (!capture->scene()) return fail(ErrorKind::BadInput, w.capture + ": needs scene.json");
  std::ifstream in(fs::path(dir) / "switch.json");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    return fail(ErrorKind::BadInput, dir + "/switch.json: " + e.what() + " (splice_switch.py writes it)");
  }
  if (!j.contains("at") || !j["at"].is_number_integer())
    return fail(ErrorKind::BadInput, dir + "/switch.json: at: must be an integer frame");
  auto est = replay_light_capture(*capture, undeclared(*capture->scene()), s);
  if (!est) return fail(est.error().kind, w.name + ": " + est.error().message);
  auto probe = load_light_truth(dir, true);
  if (!probe) return fail(probe.error().kind, w.name + ": " + probe.error().message);
  SwitchResult r;
  r.name = w.name;
  r.held_out = w.held_out;
  r.switch_frame = j["at"].get<int>();
  r.changes_noted = est->changes;
  const auto& end = est->frames.back().light;
  if (!end) return fail(ErrorKind::Internal, w.name + ": no estimate at the last frame");
  r.final_direction_deg = direction_error_deg(*end, *probe);
  const double lum_end = band0_luminance(*end);
  r.intensity_after = lum_end;
  if (r.switch_frame > 0 && size_t(r.switch_frame) <= est->frames.size())
    if (const auto& b = est->frames[size_t(r.switch_frame - 1)].light) r.intensity_before = band0_luminance(*b);
  for (size_t i = size_t(std::max(r.switch_frame, 0)); i < est->frames.size(); ++i)
    if (const auto& l = est->frames[i].light) r.series.push_back({double(i), band0_luminance(*l), direction_error_deg(*l, *probe)});
  int settled = -1;
  for (int i = int(est->frames.size()) - 1; i >= r.switch_frame; --i) {
    const auto& l = est->frames[size_t(i)].light;
    const bool ok = l && lum_end > 0.0 && std::abs(band0_luminance(*l) / lum_end - 1.0) <= 0.1 &&
                    angle_deg(l->direction_to_light, end->direction_to_light) <= 5.0;
    if (!ok) break;
    settled = i;
  }
  r.followed_after = settled < 0 ? -1 : settled - r.switch_frame;
  return r;
}

Expected<DriftResult> run_drift(const LightFamilyScene& sc, const MovingFamilySettings& ms) {
  const LightFamilySettings& s = ms.family;
  const std::string dir = (fs::path(s.root) / sc.capture).string();
  auto capture = open_rendered(dir);
  if (!capture) return capture.error();
  const size_t n = capture->frame_count();
  if (n < 2 || !capture->scene()) return fail(ErrorKind::BadInput, sc.capture + ": drift needs 2+ frames and scene.json");
  std::vector<InputFrame> frames;
  for (size_t i = 0; i < n; ++i) {
    auto f = capture->read_frame(i);
    if (!f) return f.error();
    frames.push_back(std::move(*f));
  }
  const CaptureInfo& info = capture->info();
  RuntimeSettings rs;
  rs.technique = s.technique;
  rs.level = s.level;
  rs.light_accumulate_views = s.accumulate_views;
  rs.light_near_lamps = s.near_lamps;
  rs.light_albedo_fit = s.albedo_fit;
  rs.light_near_field = s.near_field;
  rs.light_distant_views = s.distant_views;
  auto rt = create_runtime(rs, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                           undeclared(*capture->scene()));
  if (!rt) return rt.error();
  const int64_t cycle = int64_t(2 * n - 2);  // a round trip: 0 .. n-1 .. 1
  std::optional<LightEstimate> ref;
  DriftResult r;
  r.name = sc.name;
  r.frames = ms.drift_frames;
  r.settled_from = int(std::max<int64_t>(cycle, ms.drift_frames / 10));
  auto consume = [&](const std::vector<FrameOutput>& outs) {
    for (const FrameOutput& o : outs) {
      if (!o.light || !o.light->valid || o.stats.frame_index < r.settled_from) continue;
      if (!ref) ref = *o.light;
      const double dir = angle_deg(o.light->direction_to_light, ref->direction_to_light);
      const double l0 = band0_luminance(*ref);
      const double rel = l0 > 0.0 ? band0_luminance(*o.light) / l0 - 1.0 : 0.0;
      r.direction_deg = std::max(r.direction_deg, dir);
      r.intensity = std::max(r.intensity, std::abs(rel));
      if (o.stats.frame_index % 10 == 0) r.series.push_back({double(o.stats.frame_index), dir, rel});
    }
  };
  for (int64_t k = 0; k < ms.drift_frames; ++k) {
    const int64_t m = k % cycle;
    InputFrame f = frames[size_t(m < int64_t(n) ? m : cycle - m)];
    f.index = k;
    f.timestamp = double(k) / 30.0;
    auto outs = (*rt)->process(f);
    if (!outs) return outs.error();
    consume(*outs);
  }
  auto rest = (*rt)->flush();
  if (!rest) return rest.error();
  consume(*rest);
  return r;
}

}  // namespace

Expected<MovingFamilyReport> run_moving_family(const MovingFamilySettings& ms,
                                               const std::function<void(const std::string&, size_t, size_t)>& progress) {
  const LightFamilySettings& s = ms.family;
  if (s.half != "all" && s.half != "tuning" && s.half != "held-out")
    return fail(ErrorKind::BadUsage, "light moving: half '" + s.half + "': all, tuning or held-out");
  auto m = load_moving_manifest(s.manifest);
  if (!m) return m.error();
  MovingFamilyReport rep;
  std::vector<const LightFamilyScene*> scenes;
  for (const LightFamilyScene& sc : m->scenes)
    if (in_half(sc.held_out, s.half)) scenes.push_back(&sc);
  size_t switches = 0;
  for (const Manifest::Switch& w : m->switches) switches += ms.switches && in_half(w.held_out, s.half) ? 1 : 0;
  const size_t total = scenes.size() + switches + (ms.drift_frames > 0 ? 1 : 0);
  size_t done = 0;
  for (const LightFamilyScene* sc : scenes) {
    if (progress) progress(sc->name, done++, total);
    auto r = run_scene(*sc, s);
    if (!r) return r.error();
    rep.scenes.push_back(std::move(*r));
  }
  if (ms.switches)
    for (const Manifest::Switch& w : m->switches) {
      if (!in_half(w.held_out, s.half)) continue;
      if (progress) progress(w.name, done++, total);
      auto r = run_switch(w, s);
      if (!r) return r.error();
      rep.switches.push_back(*r);
    }
  if (ms.drift_frames > 0 && !scenes.empty()) {
    const LightFamilyScene* pick = scenes.front();
    for (const LightFamilyScene* sc : scenes)
      if (sc->name == ms.drift_scene) pick = sc;
    if (!ms.drift_scene.empty() && pick->name != ms.drift_scene)
      return fail(ErrorKind::BadUsage, "light moving: drift scene '" + ms.drift_scene + "' is not in the half run");
    if (progress) progress("drift: " + pick->name, done++, total);
    auto r = run_drift(*pick, ms);
    if (!r) return r.error();
    rep.drift.push_back(*r);
  }
  if (progress) progress("done", total, total);
  return rep;
}

// Every frame of each half's sweeps by the estimate's confidence: whether it says how far the
// estimate is to be trusted, and which frames the ARCore-shaped output calls valid.
std::string confidence_markdown(const MovingFamilyReport& rep) {
  std::string md =
      "\nThe estimate by its confidence (every frame of the sweeps; the ARCore-shaped output, "
      "to_environmental_hdr, is valid from a confidence of " +
      std::to_string(int(std::lround(kEnvironmentalHdrMinConfidence * 16.0f))) +
      " / 16):\n\n| half | confidence | frames | RDE ratio median / worst | direction median / worst | ARCore "
      "output |\n|---|---|---|---|---|---|\n";
  char line[256];
  for (const bool held : {false, true}) {
    std::map<int, std::pair<std::vector<double>, std::vector<double>>> by;  // sixteenths -> ratios, directions
    for (const MovingResult& r : rep.scenes) {
      if (r.scene.held_out != held) continue;
      for (const MovingFrame& f : r.frames) {
        if (!f.valid || !(f.rde_true > 0.0)) continue;
        auto& b = by[int(std::lround(f.confidence * 16.0))];
        b.first.push_back(f.rde_estimate / f.rde_true);
        b.second.push_back(f.direction_error_deg);
      }
    }
    for (auto& [k, b] : by) {
      std::snprintf(line, sizeof line, "| %s | %d / 16 | %zu | %.2f / %.2f | %.1f / %.1f | %s |\n",
                    held ? "held out" : "tuning", k, b.first.size(), median(b.first),
                    *std::max_element(b.first.begin(), b.first.end()), median(b.second),
                    *std::max_element(b.second.begin(), b.second.end()),
                    float(k) / 16.0f >= kEnvironmentalHdrMinConfidence - 1e-6f ? "valid" : "not valid");
      md += line;
    }
  }
  return md;
}

std::string moving_family_markdown(const MovingFamilyReport& rep, const MovingFamilySettings& ms) {
  std::string md;
  char line[512];
  std::snprintf(line, sizeof line,
                "Technique `%s` level %d, %s%s. Direction: degrees between the estimate's and the truth's "
                "dominant light; colour: largest per-channel error of the mean light's chromaticity, against "
                "the light sources' (probe_direct.exr) and against all the light at the objects' centre "
                "(probe.exr, bounce included); RDE ratio: estimate-lit over true-lit (all pixels).\n\n",
                ms.family.technique.c_str(), ms.family.level,
                !ms.family.accumulate_views ? "each view on its own"
                : ms.family.near_lamps      ? "the estimate accumulated over the views, near lamps found"
                                            : "the estimate accumulated over the views, distant light only",
                !(ms.family.accumulate_views && ms.family.albedo_fit) ? ""
                : ms.family.near_field ? ", albedo from interreflection, near field" : ", albedo from interreflection");
  md += line;
  if (ms.family.accumulate_views && !ms.family.distant_views)
    md += "Regions without depth not read as distant light (--no-distant-views).\n\n";
  md += "Direction error (degrees) as the sweep grows:\n\n| scene | half | 0 deg | 22 deg | 45 deg | 67 deg | 90 deg |"
        " colour after (sources / all light) | confidence after | RDE ratio, last 8 frames |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MovingResult& r : rep.scenes) {
    const size_t n = r.frames.size();
    auto at = [&](double q) { return r.frames[std::min(n - 1, size_t(std::lround(q * double(n - 1))))].direction_error_deg; };
    std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f / %.2f | %.2f | %.2f |\n",
                  r.scene.name.c_str(), r.scene.held_out ? "held out" : "tuning", at(0.0), at(0.25), at(0.5),
                  at(0.75), at(1.0), r.final_colour, r.final_colour_all, r.final_confidence, r.final_rde_ratio);
    md += line;
  }
  md += "\n| half | scenes | direction after the sweep, median / worst (target 15 / 30) | RDE ratio median / worst "
        "(target 1.2 / 1.5) | colour median / worst (target 0.10 / 0.15) | colour against all the light, median / "
        "worst |\n|---|---|---|---|---|---|\n";
  for (const bool held : {false, true}) {
    std::vector<double> dir, ratio, colour, colour_all;
    for (const MovingResult& r : rep.scenes) {
      if (r.scene.held_out != held) continue;
      dir.push_back(r.final_direction_deg);
      ratio.push_back(r.final_rde_ratio);
      colour.push_back(r.final_colour);
      colour_all.push_back(r.final_colour_all);
    }
    if (dir.empty()) continue;
    std::snprintf(line, sizeof line, "| %s | %zu | %.1f / %.1f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f |\n",
                  held ? "held out" : "tuning", dir.size(), median(dir), *std::max_element(dir.begin(), dir.end()),
                  median(ratio), *std::max_element(ratio.begin(), ratio.end()), median(colour),
                  *std::max_element(colour.begin(), colour.end()), median(colour_all),
                  *std::max_element(colour_all.begin(), colour_all.end()));
    md += line;
  }
  md += confidence_markdown(rep);
  if (!rep.switches.empty()) {
    md += "\nA lamp switched on (target: followed within 30 frames; an output frame carries the newest estimate "
          "when it is collected, up to 2 frames later with 2 in flight):\n\n| switch | half | at frame | followed after "
          "(frames) | changes detected | intensity before -> after (band 0) | direction error after |\n"
          "|---|---|---|---|---|---|---|\n";
    for (const SwitchResult& w : rep.switches) {
      std::snprintf(line, sizeof line, "| %s | %s | %d | %s | %d | %.3f -> %.3f | %.1f |\n", w.name.c_str(),
                    w.held_out ? "held out" : "tuning", w.switch_frame,
                    w.followed_after < 0 ? "never" : std::to_string(w.followed_after).c_str(), w.changes_noted,
                    w.intensity_before, w.intensity_after, w.final_direction_deg);
      md += line;
    }
  }
  for (const DriftResult& d : rep.drift) {
    std::snprintf(line, sizeof line,
                  "\nDrift: %s played back and forth for %d frames: from frame %d on the estimate's direction "
                  "moved at most %.3f degrees and its intensity %.3f %% (target 1 degree, 1 %%).\n",
                  d.name.c_str(), d.frames, d.settled_from, d.direction_deg, 100.0 * d.intensity);
    md += line;
  }
  return md;
}

std::string moving_family_json(const MovingFamilyReport& rep) {
  nlohmann::json j;
  j["scenes"] = nlohmann::json::array();
  for (const MovingResult& r : rep.scenes) {
    nlohmann::json frames = nlohmann::json::array();
    for (const MovingFrame& f : r.frames)
      frames.push_back({{"valid", f.valid}, {"direction_error_deg", f.direction_error_deg},
                        {"colour_error", f.colour_error}, {"colour_error_all_light", f.colour_error_all},
                        {"confidence", f.confidence},
                        {"rde_true", f.rde_true}, {"rde_estimate", f.rde_estimate}});
    j["scenes"].push_back({{"scene", r.scene.name}, {"held_out", r.scene.held_out},
                           {"final_direction_error_deg", r.final_direction_deg}, {"final_colour_error", r.final_colour},
                           {"final_colour_error_all_light", r.final_colour_all},
                           {"final_confidence", r.final_confidence}, {"final_rde_ratio", r.final_rde_ratio},
                           {"final_band0", r.final_band0}, {"truth_band0", r.truth_band0},
                           {"truth_all_band0", r.truth_all_band0}, {"frames", frames}});
  }
  j["switches"] = nlohmann::json::array();
  for (const SwitchResult& w : rep.switches)
    j["switches"].push_back({{"name", w.name}, {"held_out", w.held_out}, {"at", w.switch_frame},
                             {"followed_after", w.followed_after}, {"changes_detected", w.changes_noted},
                             {"intensity_before", w.intensity_before}, {"intensity_after", w.intensity_after},
                             {"final_direction_error_deg", w.final_direction_deg}, {"series", w.series}});
  j["drift"] = nlohmann::json::array();
  for (const DriftResult& d : rep.drift)
    j["drift"].push_back({{"scene", d.name}, {"frames", d.frames}, {"settled_from", d.settled_from},
                          {"direction_deg", d.direction_deg}, {"intensity", d.intensity}, {"series", d.series}});
  return j.dump(1) + "\n";
}

}  // namespace mrgi::perf
