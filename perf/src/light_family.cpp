#include "mrgi/perf/light_family.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "mrgi/light_estimate.h"
#include "mrgi/metrics.h"
#include "mrgi/perf/stats.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {
namespace {

namespace fs = std::filesystem;

}  // namespace

Expected<LightReplay> replay_light_capture(const CaptureReader& capture, const SceneDesc& scene,
                                           const LightFamilySettings& s) {
  const CaptureInfo& info = capture.info();
  RuntimeSettings rs;
  rs.technique = s.technique;
  rs.level = s.level;
  rs.device.validate = s.validate;
  rs.light_accumulate_views = s.accumulate_views;
  rs.light_near_lamps = s.near_lamps;
  rs.light_albedo_fit = s.albedo_fit;
  rs.light_near_field = s.near_field;
  rs.light_distant_views = s.distant_views;
  auto rt = create_runtime(rs, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                           scene);
  if (!rt) return rt.error();
  LightReplay run;
  run.frames.resize(capture.frame_count());
  std::vector<ImageRGB8> cameras(capture.frame_count());
  auto consume = [&](std::vector<FrameOutput>& outs) -> Status {
    for (FrameOutput& o : outs) {
      const size_t i = size_t(o.stats.frame_index);
      auto ref = capture.read_reference(i);
      if (!ref) return ref.error();
      auto mask = capture.read_reference_mask(i);
      if (!mask) return mask.error();
      auto r = measure_error(o.image, cameras[i], *ref, &*mask);
      if (!r) return r.error();
      if (!run.any) {
        run.pooled = *r;
        run.any = true;
      } else {
        run.pooled = pool(run.pooled, *r);
      }
      run.light = o.light;
      run.frames[i].rde = r->all.rde;
      run.frames[i].light = o.light;
      for (const std::string& n : o.stats.notes) {
        if (n.rfind("light:", 0) == 0) run.light_note = n;
        if (n.find("the light changed") != std::string::npos) ++run.changes;
      }
    }
    return ok_status();
  };
  for (size_t i = 0; i < capture.frame_count(); ++i) {
    auto f = capture.read_frame(i);
    if (!f) return f.error();
    f->index = int64_t(i);
    cameras[i] = f->color;
    auto outs = (*rt)->process(*f);
    if (!outs) return outs.error();
    MRGI_TRY(consume(*outs));
  }
  auto rest = (*rt)->flush();
  if (!rest) return rest.error();
  MRGI_TRY(consume(*rest));
  return run;
}

Expected<LightEstimate> load_light_truth(const std::string& capture_dir, bool direct) {
  const std::string path = (fs::path(capture_dir) / "light_probe" / (direct ? "probe_direct.exr" : "probe.exr")).string();
  auto probe = load_hdr_image(path);
  if (!probe) return fail(probe.error().kind, "the light probe: " + probe.error().message);
  auto light = light_from_environment(*probe, EnvCamera{});
  if (!light) return fail(light.error().kind, path + ": " + light.error().message);
  return *light;
}

double family_irradiance_error(const LightEstimate& est, const LightEstimate& truth) {
  constexpr int kNormals = 64;
  double err2 = 0.0, ref2 = 0.0;
  for (int k = 0; k < kNormals; ++k) {
    // Fibonacci sphere (the same spread as light::fibonacci_direction).
    const double y = 1.0 - 2.0 * (k + 0.5) / kNormals, r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double phi = 3.14159265358979323846 * (3.0 - std::sqrt(5.0)) * k;
    const std::array<float, 3> n{float(r * std::cos(phi)), float(y), float(r * std::sin(phi))};
    auto lum = [](const mrgi::Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; };
    const double e = std::max(0.0, lum(irradiance_at(est, n))), t = std::max(0.0, lum(irradiance_at(truth, n)));
    err2 += (e - t) * (e - t);
    ref2 += t * t;
  }
  return ref2 > 0.0 ? std::sqrt(err2 / ref2) : 0.0;
}

double family_colour_error(const LightEstimate& est, const LightEstimate& truth) {
  auto norm = [](const mrgi::Rgb& c) {
    const double l = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    return l > 0.0 ? std::array<double, 3>{c[0] / l, c[1] / l, c[2] / l} : std::array<double, 3>{1, 1, 1};
  };
  const auto e = norm(est.sh_radiance[0]), t = norm(truth.sh_radiance[0]);
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(e[c] - t[c]) / std::max(t[c], 1e-9));
  return worst;
}

Expected<std::vector<LightFamilyScene>> load_light_family(const std::string& path) {
  std::ifstream in(path);
  if (!in) return fail(ErrorKind::NotFound, path + ": cannot open the light family manifest");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    return fail(ErrorKind::BadInput, path + ": not JSON: " + e.what());
  }
  if (!j.is_object() || !j.contains("scenes") || !j["scenes"].is_array())
    return fail(ErrorKind::BadInput, path + ": scenes: must be an array");
  std::vector<LightFamilyScene> out;
  for (size_t i = 0; i < j["scenes"].size(); ++i) {
    const auto& s = j["scenes"][i];
    const std::string where = path + ": scenes[" + std::to_string(i) + "]";
    if (!s.is_object() || !s.contains("name") || !s["name"].is_string() || !s.contains("capture") ||
        !s["capture"].is_string() || !s.contains("held_out") || !s["held_out"].is_boolean())
      return fail(ErrorKind::BadInput, where + ": needs string name and capture, and boolean held_out");
    out.push_back({s["name"], s["capture"], s.value("varies", std::string()), s["held_out"].get<bool>()});
  }
  if (out.empty()) return fail(ErrorKind::BadInput, path + ": scenes: empty");
  return out;
}

Expected<std::vector<LightFamilyResult>> run_light_family(const LightFamilySettings& s,
                                                          const std::function<void(const std::string&, size_t, size_t)>& progress) {
  auto all = load_light_family(s.manifest);
  if (!all) return all.error();
  if (s.half != "all" && s.half != "tuning" && s.half != "held-out")
    return fail(ErrorKind::BadUsage, "light family: half '" + s.half + "': all, tuning or held-out");
  std::optional<std::vector<LightFamilyScene>> scenes(std::in_place);
  for (const LightFamilyScene& sc : *all)
    if (s.half == "all" || sc.held_out == (s.half == "held-out")) scenes->push_back(sc);
  std::vector<LightFamilyResult> results;
  for (size_t k = 0; k < scenes->size(); ++k) {
    const LightFamilyScene& sc = (*scenes)[k];
    if (progress) progress(sc.name, k, scenes->size());
    auto capture = CaptureReader::open((fs::path(s.root) / sc.capture).string());
    if (!capture) return capture.error();
    if (!capture->scene() || !capture->has_references())
      return fail(ErrorKind::BadInput, sc.capture + ": a family capture needs scene.json and references");
    const SceneDesc& truth_scene = *capture->scene();
    SceneDesc undeclared = truth_scene;
    undeclared.lights.clear();
    undeclared.environment = EnvironmentDesc{};
    auto truth = replay_light_capture(*capture, truth_scene, s);
    if (!truth) return fail(truth.error().kind, sc.name + " (true light): " + truth.error().message);
    auto est = replay_light_capture(*capture, undeclared, s);
    if (!est) return fail(est.error().kind, sc.name + " (estimate): " + est.error().message);
    if (!est->light) return fail(ErrorKind::Internal, sc.name + ": the estimate-lit run gave no light estimate");
    // The truth: the light sources as the virtual objects' centre sees them (mrgi synth's
    // light_probe/probe_direct.exr: environment and lamps where no real surface is in the way);
    // the irradiance's truth is everything that reaches the object, bounce light included
    // (probe.exr, path-traced): that is what lights it.
    const std::string dir = (fs::path(s.root) / sc.capture).string();
    auto probe_light = load_light_truth(dir, true);
    if (!probe_light) return fail(probe_light.error().kind, sc.name + ": " + probe_light.error().message);
    auto full_light = load_light_truth(dir, false);
    if (!full_light) return fail(full_light.error().kind, sc.name + ": " + full_light.error().message);
    LightFamilyResult r;
    r.scene = sc;
    r.estimate_source = est->light_note;
    r.direction_error_deg = direction_error_deg(*est->light, *probe_light);
    r.irradiance_error = family_irradiance_error(*est->light, *full_light);
    r.colour_error = family_colour_error(*est->light, *probe_light);
    r.confidence = est->light->confidence;
    r.estimate_direction = est->light->direction_to_light;
    r.truth_direction = probe_light->direction_to_light;
    r.estimate_mean = est->light->sh_radiance[0];
    r.truth_mean = probe_light->sh_radiance[0];
    r.truth_all_mean = full_light->sh_radiance[0];
    r.rde_true = truth->pooled.all.rde;
    r.rde_estimate = est->pooled.all.rde;
    r.sky = sc.name.rfind("sky", 0) == 0;
    results.push_back(r);
  }
  if (progress) progress("done", scenes->size(), scenes->size());
  return results;
}

std::string light_family_markdown(const std::vector<LightFamilyResult>& results, const LightFamilySettings& s) {
  std::string md;
  char line[512];
  std::snprintf(line, sizeof line,
                "Technique `%s` level %d. Direction: degrees between the estimate's and the truth's dominant "
                "light; irradiance: relative RMS error of E(n) over 64 normals; colour: largest per-channel "
                "error of the mean light's chromaticity; RDE ratio: estimate-lit over true-lit.\n\n",
                s.technique.c_str(), s.level);
  md += line;
  md += "| scene | half | direction (deg) | irradiance | colour | confidence | RDE true | RDE estimate | ratio |\n";
  md += "|---|---|---|---|---|---|---|---|---|\n";
  for (const LightFamilyResult& r : results) {
    std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.2f | %.2f | %.2f | %.3f | %.3f | %.2f |\n",
                  r.scene.name.c_str(), r.scene.held_out ? "held out" : "tuning", r.direction_error_deg,
                  r.irradiance_error, r.colour_error, r.confidence, r.rde_true, r.rde_estimate, r.rde_ratio());
    md += line;
  }
  md += "\n| half | scenes | direction median / worst (target 15 / 30) | irradiance median | colour worst, sky "
        "scenes (target 0.10) | RDE ratio median / worst (target 1.15) |\n|---|---|---|---|---|---|\n";
  for (const bool held : {false, true}) {
    std::vector<double> dir, irr, ratio;
    double colour = 0.0;
    for (const LightFamilyResult& r : results) {
      if (r.scene.held_out != held) continue;
      dir.push_back(r.direction_error_deg);
      irr.push_back(r.irradiance_error);
      ratio.push_back(r.rde_ratio());
      if (r.sky) colour = std::max(colour, r.colour_error);
    }
    if (dir.empty()) continue;
    std::snprintf(line, sizeof line, "| %s | %zu | %.1f / %.1f | %.2f | %.2f | %.2f / %.2f |\n",
                  held ? "held out" : "tuning", dir.size(), median(dir), *std::max_element(dir.begin(), dir.end()),
                  median(irr), colour, median(ratio), *std::max_element(ratio.begin(), ratio.end()));
    md += line;
  }
  return md;
}

std::string light_family_json(const std::vector<LightFamilyResult>& results) {
  nlohmann::json j = nlohmann::json::array();
  for (const LightFamilyResult& r : results)
    j.push_back({{"scene", r.scene.name}, {"held_out", r.scene.held_out}, {"source", r.estimate_source},
                 {"direction_error_deg", r.direction_error_deg}, {"irradiance_error", r.irradiance_error},
                 {"colour_error", r.colour_error}, {"confidence", r.confidence}, {"rde_true", r.rde_true},
                 {"rde_estimate", r.rde_estimate}, {"rde_ratio", r.rde_ratio()},
                 {"estimate_direction", r.estimate_direction}, {"truth_direction", r.truth_direction},
                 {"estimate_band0", r.estimate_mean}, {"truth_band0", r.truth_mean},
                 {"truth_all_band0", r.truth_all_mean}});
  return j.dump(1) + "\n";
}

}  // namespace mrgi::perf
