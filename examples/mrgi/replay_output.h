// What `mrgi replay` and `mrgi live` write to --out DIR:
//   DIR/frames/NNNNNN.png   composited RGBA8 frames (--output composite, the default)
//   DIR/overlay/NNNNNN.png  the composite as a premultiplied overlay for a passthrough
//                           compositor (--output overlay; mrgi/overlay.h: the blend, what it
//                           cannot express)
//   DIR/stats.json          per frame: each pass's ms, total ms, record ms, level, internal scale,
//                           cost, predicted cost and budget (the scheduler's view), skipped passes,
//                           notes (a priming run, a missing pose), the frame's error figures
//                           when a reference exists, and the estimated light (ssrt) when the
//                           technique estimates one
//   DIR/summary.json        frames; the headline frame time sustained_ms (wall clock per frame
//                           with inputs preloaded and frames in flight, as `mrgi bench` names it)
//                           and cpu_ms (process CPU per frame) beside it; median_device_ms and
//                           p95_device_ms (GPU timestamps, or the passes' sum when profiled);
//                           passes_ms_are (whether per-pass times can be trusted on this device);
//                           achieved {fps, ms_per_frame} (end to end, PNG I/O included),
//                           technique, level, device, budget {share_within, level_switches,
//                           frames_per_level, median and p95 cost},
//                           lp_num_threads, memory_mib, rde {all, real, virtual} with references,
//                           and light_direction_error_deg {median, worst, frames} when the
//                           capture has environment images and the technique estimates light
//   DIR/side_by_side.png    camera | mrgi | reference | difference x4 (or camera | mrgi) of the
//                           last frame, labelled
// and, with --video FILE, the composited frames as a clip (video_output.h).
// Everything is written under DIR.partial and renamed over DIR by finish(), so a failed run leaves
// no half-written output behind.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mrgi/platform/output_dir.h"
#include "mrgi/metrics.h"
#include "mrgi/runtime.h"
#include "video_output.h"

namespace mrgi::tool {

struct ReplayMeta {
  std::string source;     // capture folder or live source
  std::string technique;
  int level = 0;
  std::string level_name;
  std::string device;
  bool cpu_device = false;  // a CPU Vulkan device (lavapipe): GPU timestamps do not time passes
  double memory_mib = 0.0;
  int width = 0, height = 0;
};

class ReplayOutput {
 public:
  static Expected<ReplayOutput> create(const std::string& dir, const ReplayMeta& meta);
  // camera: the input colour frame at output size; reference/mask optional (capture references).
  // light_truth: the light of the frame's environment image (light_from_environment), when the
  // capture has one; with an estimate it gives the frame's direction error.
  Status add(const FrameOutput& out, const ImageRGB8& camera, const ImageRGB8* reference,
             const ImageU8* mask, const LightEstimate* light_truth = nullptr);
  // Writes stats.json, summary.json and the side-by-side image, then renames DIR.partial to DIR.
  Expected<nlohmann::json> finish();
  size_t frames() const { return frame_ms_.size(); }
  // The command's own rate over the run (summary.json "achieved"): frames over wall seconds.
  struct Achieved {
    size_t frames = 0;
    double seconds = 0.0;
    std::string what;  // what the interval covers
  };
  void set_achieved(const Achieved& a) { achieved_ = a; }
  // The headline (summary.json "sustained_ms", "cpu_ms"): the frames alone, processed back to
  // back with their inputs already decoded; absent where the frames ran beside I/O.
  struct Sustained {
    double wall_seconds = 0.0, cpu_seconds = 0.0;
    size_t frames = 0;
    int frames_in_flight = 0;
  };
  void set_sustained(const Sustained& s) { sustained_ = s; }
  // Which images each frame writes: the composite (frames/), the passthrough overlay
  // (overlay/, mrgi/overlay.h); at least one.
  Status set_images(bool composite, bool overlay);
  // The composited frames also go to this clip (--video), finished with the rest.
  void set_video(VideoOutput&& video) { video_.emplace(std::move(video)); }

 private:
  std::optional<OutputDir> output_;
  std::optional<VideoOutput> video_;
  bool write_composite_ = true, write_overlay_ = false;
  std::string dir_, partial_;
  ReplayMeta meta_;
  nlohmann::json stats_ = nlohmann::json::array();
  std::vector<double> frame_ms_;
  std::vector<double> cost_ms_;   // FrameStats::cost_ms
  std::vector<int> levels_;
  double budget_ms_ = 0.0;
  bool profiled_ = false;
  Achieved achieved_;
  Sustained sustained_;
  std::optional<RdeReport> pooled_;
  ImageRGB8 side_by_side() const;
  ImageRGB8 last_camera_, last_reference_;
  ImageRGBA8 last_output_;
  nlohmann::json last_light_;
  std::vector<double> light_error_deg_;
};

// The estimated light (techniques that estimate it): direction, intensity, confidence, SH.
nlohmann::json light_json(const LightEstimate& e);

}  // namespace mrgi::tool
