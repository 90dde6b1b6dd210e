#include "replay_output.h"

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/report.h"
#include "mrgi/perf/stats.h"
#include "mrgi/overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace mrgi::tool {
namespace {

Status write_json(const std::string& path, const nlohmann::json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    if (!f) return fail(ErrorKind::Device, tmp + ": cannot open for writing");
    f << j.dump(2) << "\n";
    if (!f) return fail(ErrorKind::Device, tmp + ": write failed");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) return fail(ErrorKind::Device, path + ": rename failed: " + ec.message());
  return ok_status();
}

std::string frame_name(size_t i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06zu.png", i);
  return buf;
}

int lp_num_threads() {
  const char* v = std::getenv("LP_NUM_THREADS");
  return v ? std::atoi(v) : 0;  // 0 = not set (lavapipe then uses one thread per core)
}

}  // namespace



Expected<ReplayOutput> ReplayOutput::create(const std::string& dir, const ReplayMeta& meta) {
  ReplayOutput out;
  // Only an earlier mrgi output (or an empty folder) is replaced, and a failed run removes its
  // own DIR.partial (mrgi/platform/output_dir.h).
  auto od = OutputDir::begin(dir, "--out");
  if (!od) return od.error();
  out.output_.emplace(std::move(*od));
  out.dir_ = out.output_->dir();
  out.partial_ = out.output_->partial();
  out.meta_ = meta;
  std::error_code ec;
  fs::create_directories(out.partial_ + "/frames", ec);
  if (ec) return fail(ErrorKind::BadInput, out.partial_ + ": cannot create output folder: " + ec.message());
  return out;
}

nlohmann::json light_json(const LightEstimate& e) {
  nlohmann::json sh = nlohmann::json::array();
  for (int i = 0; i < e.bands * e.bands; ++i) sh.push_back(e.sh_radiance[size_t(i)]);
  return {{"valid", e.valid},
          {"solved_from_frame", e.frame_index},
          {"direction_to_light", e.direction_to_light},
          {"dominant_intensity", e.dominant_intensity},
          {"confidence", e.confidence},
          {"bands", e.bands},
          {"sh_radiance", sh}};
}

Status ReplayOutput::set_images(bool composite, bool overlay) {
  if (!composite && !overlay) return fail(ErrorKind::BadUsage, "--output: name at least one of composite, overlay");
  write_composite_ = composite;
  write_overlay_ = overlay;
  std::error_code ec;
  if (!composite) {
    fs::remove(partial_ + "/frames", ec);
    if (ec) return fail(ErrorKind::BadInput, partial_ + "/frames: cannot remove the empty folder: " + ec.message());
  }
  if (overlay) {
    fs::create_directories(partial_ + "/overlay", ec);
    if (ec) return fail(ErrorKind::BadInput, partial_ + "/overlay: cannot create output folder: " + ec.message());
  }
  return ok_status();
}

Status ReplayOutput::add(const FrameOutput& out, const ImageRGB8& camera, const ImageRGB8* reference,
                         const ImageU8* mask, const LightEstimate* light_truth) {
  const size_t i = frame_ms_.size();
  if (write_composite_) MRGI_TRY(write_png(partial_ + "/frames/" + frame_name(i), out.image));
  if (write_overlay_) {
    auto overlay = make_overlay(out.image, out.virtual_mask, camera);
    if (!overlay) return overlay.error();
    MRGI_TRY(write_png(partial_ + "/overlay/" + frame_name(i), *overlay));
  }
  if (video_) MRGI_TRY(video_->add(out.image));
  nlohmann::json s;
  s["frame"] = out.stats.frame_index;
  s["level"] = out.stats.level;
  s["internal_scale"] = out.stats.internal_scale;
  s["cost_ms"] = out.stats.cost_ms;
  s["predicted_ms"] = out.stats.predicted_ms;
  s["budget_ms"] = out.stats.budget_ms;
  s["scheduled"] = out.stats.scheduled;
  s["gpu_total_ms"] = out.stats.gpu_total_ms;
  s["record_ms"] = out.stats.record_ms;
  s["light_ms"] = out.stats.light_ms;
  nlohmann::json passes = nlohmann::json::object();
  for (const auto& p : out.stats.passes) passes[p.name] = p.gpu_ms;
  s["passes_ms"] = passes;
  s["skipped"] = out.stats.skipped;
  s["notes"] = out.stats.notes;  // e.g. the priming run, a frame without a pose
  if (out.light) {
    s["light"] = light_json(*out.light);
    last_light_ = s["light"];
    if (light_truth && out.light->valid) {
      const double err = direction_error_deg(*out.light, *light_truth);
      s["light_truth"] = light_json(*light_truth);
      s["light_direction_error_deg"] = err;
      light_error_deg_.push_back(err);
    }
  }
  if (reference) {
    auto r = measure_error(out.image, camera, *reference, mask);
    if (!r.ok()) return r.error();
    s["error"] = perf::error_report_json(*r);
    if (!pooled_) {
      pooled_ = *r;
    } else {
      *pooled_ = pool(*pooled_, *r);
    }
    last_reference_ = *reference;
  }
  stats_.push_back(std::move(s));
  frame_ms_.push_back(out.stats.gpu_total_ms);
  cost_ms_.push_back(out.stats.cost_ms);
  levels_.push_back(out.stats.level);
  budget_ms_ = out.stats.budget_ms;
  profiled_ = profiled_ || out.stats.profiled;
  last_camera_ = camera;
  last_output_ = out.image;
  return ok_status();
}

Expected<nlohmann::json> ReplayOutput::finish() {
  nlohmann::json summary;
  summary["frames"] = frame_ms_.size();
  if (sustained_.frames > 0 && sustained_.wall_seconds > 0.0) {
    const double n = double(sustained_.frames);
    summary["sustained_ms"] = 1000.0 * sustained_.wall_seconds / n;
    summary["cpu_ms"] = 1000.0 * sustained_.cpu_seconds / n;
    summary["sustained_is"] = "the headline frame time: wall clock per frame of the frames processed back to back, "
                              "inputs decoded beforehand, " + std::to_string(sustained_.frames_in_flight) +
                              " in flight (decoding, error figures and PNG writing outside); cpu_ms: process CPU per "
                              "frame over the same intervals" +
                              std::string(profiled_ ? " (profiling mode: passes submitted one by one, slower than a "
                                                      "normal frame)" : "");
  } else {
    summary["sustained_ms"] = nullptr;
    summary["sustained_is"] = sustained_.frames_in_flight > 0
                                  ? "not measured: too few frames (the window opens at the first output)"
                                  : "not measured: the frames ran beside decoding and writing (--io overlapped, or live)";
  }
  summary["median_device_ms"] = perf::percentile(frame_ms_, 50);
  summary["p95_device_ms"] = perf::percentile(frame_ms_, 95);
  summary["device_ms_is"] = profiled_ ? "sum of the passes, each submitted alone and host-timed (profiling mode)"
                                      : "GPU time of the frame graph (first to last timestamp), per frame";
  summary["passes_ms_are"] =
      profiled_ ? "profiled: each pass submitted alone and host-timed (stats.json passes_ms)"
      : meta_.cpu_device
          ? "unreliable: GPU timestamps on a CPU device (lavapipe) do not bracket each pass's work; --profile "
            "for per-pass times"
          : "GPU timestamps (stats.json passes_ms)";
  if (achieved_.seconds > 0.0 && achieved_.frames > 0) {
    // What a user of the command saw: every frame decoded, processed and encoded, end to end.
    summary["achieved"] = {{"frames", achieved_.frames},
                           {"seconds", achieved_.seconds},
                           {"fps", double(achieved_.frames) / achieved_.seconds},
                           {"ms_per_frame", 1000.0 * achieved_.seconds / double(achieved_.frames)},
                           {"is", achieved_.what}};
  }
  if (!cost_ms_.empty()) {
    // What the scheduler held: every frame's cost (device + own host work) against the budget,
    // the level it ran at and how often the level changed.
    size_t within = 0, switches = 0;
    nlohmann::json per_level = nlohmann::json::object();
    for (size_t i = 0; i < cost_ms_.size(); ++i) {
      within += cost_ms_[i] <= budget_ms_;
      if (i > 0 && levels_[i] != levels_[i - 1]) ++switches;
      const std::string k = std::to_string(levels_[i]);
      per_level[k] = per_level.value(k, 0) + 1;
    }
    summary["budget"] = {{"budget_ms", budget_ms_},
                         {"frames_within", within},
                         {"share_within", double(within) / double(cost_ms_.size())},
                         {"median_cost_ms", perf::percentile(cost_ms_, 50)},
                         {"p95_cost_ms", perf::percentile(cost_ms_, 95)},
                         {"level_switches", switches},
                         {"frames_per_level", per_level},
                         {"cost_is", "device time + the frame's own host work (a CPU device), or the larger (a GPU)"}};
  }
  summary["technique"] = meta_.technique;
  summary["level"] = meta_.level;
  summary["level_name"] = meta_.level_name;
  summary["device"] = meta_.device;
  summary["lp_num_threads"] = lp_num_threads();
  summary["memory_mib"] = meta_.memory_mib;
  summary["width"] = meta_.width;
  summary["height"] = meta_.height;
  summary["source"] = meta_.source;
  if (!last_light_.is_null()) summary["light"] = last_light_;
  if (!light_error_deg_.empty()) {
    summary["light_direction_error_deg"] = {
        {"median", perf::percentile(light_error_deg_, 50)},
        {"worst", *std::max_element(light_error_deg_.begin(), light_error_deg_.end())},
        {"frames", light_error_deg_.size()},
        {"truth", "dominant direction (SH band 1) of the frame's environment image"}};
  }
  if (pooled_) {
    auto rde = [](const ErrorFigures& f) { return f.rde_defined ? nlohmann::json(f.rde) : nlohmann::json(nullptr); };
    summary["rde"] = {{"all", rde(pooled_->all)},
                      {"real", rde(pooled_->real)},
                      {"virtual", rde(pooled_->virtual_)},
                      {"influenced", rde(pooled_->influenced)},
                      {"rest", rde(pooled_->rest)},
                      {"darkened", rde(pooled_->darkened)},
                      {"brightened", rde(pooled_->brightened)},
                      {"silhouette", rde(pooled_->silhouette)}};
    summary["error"] = perf::error_report_json(*pooled_);
  }
  MRGI_TRY(write_json(partial_ + "/stats.json", stats_));
  MRGI_TRY(write_json(partial_ + "/summary.json", summary));
  if (!last_output_.empty()) MRGI_TRY(write_png(partial_ + "/side_by_side.png", side_by_side()));
  if (video_) MRGI_TRY(video_->finish());
  MRGI_TRY(output_->commit());
  return summary;
}

// camera | mrgi | reference | |mrgi - reference| x 4, each panel under a label (the last two
// only when the capture has references), so the picture says what it shows by itself.
ImageRGB8 ReplayOutput::side_by_side() const {
  const int w = last_output_.width, h = last_output_.height;
  const bool ref = !last_reference_.empty() && last_reference_.width == w && last_reference_.height == h;
  const int panels = ref ? 4 : 2;
  const float scale = std::max(1.0f, float(w) / 320.0f);
  const int bar = int(perf::Canvas::text_height(scale) + 8.0f * scale);
  const char* labels[4] = {"camera", "mrgi", "reference (path traced)", "|mrgi - reference| x 4"};
  ImageRGB8 panel(w * panels, h + bar);
  std::fill(panel.data.begin(), panel.data.end(), uint8_t(24));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        panel.at(x, y + bar)[c] = last_camera_.at(x, y)[c];
        panel.at(x + w, y + bar)[c] = last_output_.at(x, y)[c];
        if (!ref) continue;
        const int o = last_output_.at(x, y)[c], g = last_reference_.at(x, y)[c];
        panel.at(x + 2 * w, y + bar)[c] = uint8_t(g);
        panel.at(x + 3 * w, y + bar)[c] = uint8_t(std::min(255, 4 * std::abs(o - g)));
      }
  perf::Canvas labelled(std::move(panel));
  for (int i = 0; i < panels; ++i)
    labelled.text(float(i * w) + 4.0f * scale, 4.0f * scale, labels[i], scale, perf::Rgb{235, 235, 235});
  return labelled.image();
}

}  // namespace mrgi::tool
