// mrgi replay CAPTURE --technique NAME --out DIR [--level N|last] [--frames N] [--width W --height H]
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <iostream>
#include <memory>

#include "ablation_names.h"
#include "commands.h"
#include "live_view.h"
#include "mrgi/platform/apriltag.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "replay_output.h"
#include "stage_thread.h"

namespace mrgi::tool {
namespace {

struct ReplayOptions {
  std::string capture, out, device, light = "declared", video, io;
  QualityOptions quality;
  std::vector<std::string> dlpv_ablation;
  std::vector<std::string> dir_ablation;
  std::vector<std::string> specular_ablation;
  OutputImagesOption output_images;
  int frames = 0, width = 0, height = 0, preload_frames = 0;
  bool validate = false, quiet = false, vulkan_1_2 = false, no_residual_light = false, profile = false;
  bool single_view_light = false;
  bool no_albedo_fit = false;
  bool no_near_field = false;
  bool no_distant_views = false;
  ViewOptions view;
};

// The settings the options give beyond the quality (o.quality.apply): device, output size,
// light and ablations; the capture gives the exposure.
void apply_options(const ReplayOptions& o, const CaptureInfo& info, RuntimeSettings& settings) {
  settings.device.device = o.device;
  settings.device.validate = o.validate;
  settings.profile_passes = o.profile;
  settings.device.vulkan_1_2 = o.vulkan_1_2;
  settings.residual_light = !o.no_residual_light;
  settings.light_accumulate_views = !o.single_view_light;
  settings.light_albedo_fit = !o.no_albedo_fit;
  settings.light_near_field = !o.no_near_field;
  settings.light_distant_views = !o.no_distant_views;
  settings.output_width = o.width;
  settings.output_height = o.height;
  settings.exposure = info.exposure;
  ResearchSettings research;
  set_ablations(o.dlpv_ablation, kDlpvAblations, research.dlpv);
  if (research.dlpv.any() && o.quality.technique != "dlpv")
    throw CommandFailure(2, "--dlpv-ablation: only for --technique dlpv");
  set_ablations(o.dir_ablation, kDirAblations, research.dir);
  if (research.dir.any() && o.quality.technique != "dir")
    throw CommandFailure(2, "--dir-ablation: only for --technique dir");
  set_ablations(o.specular_ablation, kSpecularAblations, research.specular);
  if (research.any()) settings.research = std::make_shared<const ResearchSettings>(research);
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Decoded {
  InputFrame frame;
  ImageRGB8 camera;                     // the colour frame at output size
  std::optional<LightEstimate> truth;   // the light of the frame's environment image
};
struct Finished {
  FrameOutput output;
  ImageRGB8 camera;
  std::optional<LightEstimate> truth;
};

// One replay's frames through the runtime, in one of the two I/O modes (run_preloaded,
// run_overlapped), with what both share: the input side, the output side, the frames between.
struct Replay {
  const ReplayOptions& o;
  CaptureReader& capture;
  const CaptureInfo& info;
  const size_t frames;
  const int out_w, out_h;
  const double env_intensity;
  Runtime* runtime;
  ReplayOutput& output;
  std::optional<AprilTagTracker>& tracker;
  size_t tracked = 0, untracked = 0;
  size_t written = 0;
  std::chrono::steady_clock::time_point t0;
  // run_preloaded: wall-clock and process CPU seconds of the chunks' frames alone (from a chunk's
  // first output to its flush(), no decoding or encoding inside) and the frames completed in
  // them, for the sustained figure.
  double frames_seconds = 0.0, frames_cpu_seconds = 0.0;
  size_t sustained_frames = 0;
  // Outputs come back frames_in_flight calls late (Runtime::process): each input's camera frame
  // and true light wait here until then.
  std::vector<std::optional<Decoded>> in_flight;
  // --view: the window each composite is shown in as it is written, and the runtime with the
  // next technique for its T key (made on the view's device; the current one's frames flushed).
  LiveView* view = nullptr;
  std::function<Runtime*()> next_technique;
  bool technique_requested = false, stopped = false;

  // One frame's input side (PNG reads, AprilTag, the environment's true light) and output side
  // (the reference read, error figures, PNG write), shared by both I/O modes.
  Decoded decode_one(size_t i) {
    Decoded d;
    d.frame = take(capture.read_frame(i));
    d.frame.index = int64_t(i);
    if (!d.frame.pose && tracker) {
      tracker->fill_pose(d.frame);
      ++(d.frame.pose ? tracked : untracked);
    }
    d.camera = resize_bilinear(d.frame.color, out_w, out_h);
    if (d.frame.env && info.env_camera)
      d.truth = take(light_from_environment(*d.frame.env, *info.env_camera, env_intensity));
    return d;
  }
  void encode_one(Finished& f) {
    const size_t i = size_t(f.output.stats.frame_index);
    std::optional<ImageRGB8> ref;
    std::optional<ImageU8> mask;
    if (!capture.entry(i).reference.empty()) {
      ref = resize_bilinear(take(capture.read_reference(i)), out_w, out_h);
      if (!capture.entry(i).reference_mask.empty())
        mask = resize_nearest(take(capture.read_reference_mask(i)), out_w, out_h);
    }
    const LightEstimate* truth = f.truth ? &*f.truth : nullptr;
    auto st = output.add(f.output, f.camera, ref ? &*ref : nullptr, mask ? &*mask : nullptr, truth);
    if (!st.ok()) fail_with(st.error());
    ++written;
    if (!o.quiet)
      progress("replay " + o.quality.technique, written, frames,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (view) present(f);
  }
  // Shows the frame and takes the keys' requests: a level applies from the next frame on, a
  // technique between chunks (the view runs chunks of one frame), quit ends the replay there.
  void present(const Finished& f) {
    if (Status s = view->show(f.output.image, f.camera, view_status(*runtime, f.output.stats)); !s.ok()) fail_with(s.error());
    const ViewRequests r = view->poll();
    stopped = stopped || r.quit;
    technique_requested = technique_requested || r.next_technique;
    if (Status s = step_level(*runtime, f.output.stats, r.level_step); !s.ok()) fail_with(s.error());
  }
  Finished finish(FrameOutput&& f) {
    const size_t i = size_t(f.stats.frame_index);
    Finished item{std::move(f), std::move(in_flight[i]->camera), std::move(in_flight[i]->truth)};
    in_flight[i].reset();
    return item;
  }
  void run_preloaded();
  void run_overlapped();
};

// Chunks of inputs decoded before their frames run and encoded after: the runtime's frames
// have the cores to themselves, as on a live device, so the costs the scheduler holds to the
// budget are the runtime's (on 2 cores, overlapped PNG I/O makes the same frame cost 13 to
// 27 ms). A chunk is as many frames as fit in kChunkBytes; the replay hands the runtime a
// ready output buffer for each frame it takes (recycle), so no frame pays for fresh pages.
void Replay::run_preloaded() {
  constexpr size_t kChunkBytes = size_t(512) << 20;
  const size_t in_px = size_t(info.color.width) * size_t(info.color.height);
  const size_t out_px = size_t(out_w) * size_t(out_h);
  const size_t frame_bytes = in_px * 5 + out_px * 8 + 1;
  // With --view a chunk is one frame: each is shown as it completes and the keys act at once.
  const size_t chunk = view ? 1
                     : o.preload_frames > 0 ? std::min(size_t(o.preload_frames), frames)
                                            : std::clamp<size_t>(kChunkBytes / frame_bytes, 4, frames);
  std::vector<FrameOutput> spares(chunk + 4);
  for (FrameOutput& s : spares) {
    s.image = ImageRGBA8(out_w, out_h);
    s.virtual_mask = ImageU8(out_w, out_h);
  }
  std::vector<Finished> done;
  done.reserve(chunk + 4);
  for (size_t first = 0; first < frames && !stopped; first += chunk) {
    const size_t last = std::min(frames, first + chunk);
    for (size_t i = first; i < last; ++i) in_flight[i] = decode_one(i);
    // Completion to completion, as the bench's sustained phase: the window opens when the
    // chunk's first outputs come back (the pipeline filled, frame 0's start-up behind it) and
    // closes at the flush; the outputs after that first batch are the frames it holds (a chunk
    // whose outputs all come back at once, as the flush of a run no longer than the frames in
    // flight, holds none: no sustained figure rather than 0 ms).
    std::optional<std::chrono::steady_clock::time_point> wall0;
    double cpu0 = 0.0;
    auto collect = [&](std::vector<FrameOutput>&& outs) {
      if (outs.empty()) return;
      if (!wall0) {
        wall0 = std::chrono::steady_clock::now();
        cpu0 = process_cpu_seconds();
      } else {
        sustained_frames += outs.size();
      }
      for (FrameOutput& f : outs) done.push_back(finish(std::move(f)));
    };
    for (size_t i = first; i < last; ++i) {
      if (!spares.empty()) {
        runtime->recycle(std::move(spares.back()));
        spares.pop_back();
      }
      auto outs = take(runtime->process(in_flight[i]->frame));
      in_flight[i]->frame = InputFrame{};
      collect(std::move(outs));
    }
    collect(take(runtime->flush()));
    if (wall0) {
      frames_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - *wall0).count();
      frames_cpu_seconds += process_cpu_seconds() - cpu0;
    }
    for (Finished& f : done) {
      encode_one(f);
      spares.push_back(std::move(f.output));
    }
    done.clear();
    if (technique_requested && next_technique) {
      runtime = next_technique();
      technique_requested = false;
    }
  }
}

// Three stages, each on its own thread, with at most kQueued items between two of them:
// decode -> the runtime -> encode. The runtime stage never waits on file I/O, but on a
// machine with few cores the I/O stages take cores from the frames (their costs are noisy).
void Replay::run_overlapped() {
  constexpr size_t kQueued = 2;
  BoundedQueue<Decoded> decoded(kQueued);
  BoundedQueue<Finished> finished(kQueued);
  ReturnQueue<FrameOutput> encoded;  // outputs written, for Runtime::recycle
  StageThread decode(
      [&] {
        for (size_t i = 0; i < frames; ++i)
          if (!decoded.push(decode_one(i))) return;  // a later stage failed
      },
      [&] { decoded.close(); });
  StageThread encode(
      [&] {
        while (auto f = finished.pop()) {
          encode_one(*f);
          encoded.put(std::move(f->output));
        }
      },
      [&] {
        finished.close();
        decoded.close();  // unblocks the decoder if encoding failed
      });
  auto hand_on = [&](std::vector<FrameOutput>&& outs) {
    for (FrameOutput& f : outs)
      if (!finished.push(finish(std::move(f)))) return false;
    return true;
  };
  try {
    bool ok = true;
    while (ok) {
      auto d = decoded.pop();
      if (!d) break;
      const size_t i = size_t(d->frame.index);
      for (FrameOutput& done : encoded.take_all()) runtime->recycle(std::move(done));
      auto outs = runtime->process(d->frame);
      in_flight[i] = std::move(d);
      in_flight[i]->frame = InputFrame{};
      ok = hand_on(take(std::move(outs)));
    }
    if (ok) hand_on(take(runtime->flush()));
  } catch (...) {
    decoded.close();
    finished.close();
    throw;
  }
  finished.close();
  decode.join();
  encode.join();
}

// stdout's one line a run (the figures are in summary.json): what ran, the headline frame time
// and the error against the references when the capture has them.
std::string replay_line(const nlohmann::json& summary, const std::string& out) {
  char buf[160];
  std::string line = summary.value("technique", "") + " " + summary.value("level_name", "") + ", " +
                     std::to_string(summary.value("frames", 0)) + " frames";
  if (summary["sustained_ms"].is_number()) {
    std::snprintf(buf, sizeof buf, ": sustained %.1f ms a frame, CPU %.1f ms", summary["sustained_ms"].get<double>(),
                  summary["cpu_ms"].get<double>());
    line += buf;
  } else {
    line += ": sustained ms " + summary.value("sustained_is", std::string("not measured"));
  }
  if (summary.contains("rde")) {
    auto fig = [&](const char* k) {
      const auto& v = summary["rde"][k];
      if (!v.is_number()) return std::string("-");
      std::snprintf(buf, sizeof buf, "%.3f", v.get<double>());
      return std::string(buf);
    };
    line += "; RDE all " + fig("all") + ", real " + fig("real") + ", virtual " + fig("virtual");
  }
  return line + "; " + out + "/summary.json";
}

void run_replay(const ReplayOptions& o) {
  if ((o.width == 0) != (o.height == 0)) throw CommandFailure(2, "--width and --height go together");
  RuntimeSettings settings;
  o.quality.apply(settings);  // before any file is opened: a bad level or knob ends here
  const int level = settings.level;
  if (!o.video.empty())
    if (Status st = VideoOutput::check(o.video, o.out); !st.ok()) fail_with(st.error());
  CaptureReader capture = take(CaptureReader::open(o.capture));
  const CaptureInfo& info = capture.info();
  const size_t frames = o.frames > 0 ? std::min<size_t>(size_t(o.frames), capture.frame_count()) : capture.frame_count();
  if (frames == 0) throw CommandFailure(1, o.capture + ": capture has no frames");

  apply_options(o, info, settings);
  CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  SceneDesc scene = capture.scene() ? *capture.scene() : SceneDesc{};
  // The env intensity stays known for the truth of the direction error (env frames).
  const double env_intensity = scene.environment.present ? scene.environment.intensity : 1.0;
  if (o.light == "estimate") {  // what an app that declares nothing sees: the runtime's estimate
    scene.lights.clear();
    scene.environment = EnvironmentDesc{};
  }
  const int out_w = o.width ? o.width : info.color.width, out_h = o.height ? o.height : info.color.height;
  // --view: the window's own device (the view is the app), mrgi on it; declared before the
  // runtime so that it outlives it.
  std::unique_ptr<LiveView> view;
  if (o.view.view) {
    if (o.io == "overlapped") throw CommandFailure(2, "--view: frames are shown as they complete with --io preloaded only");
    view = take(LiveView::open("mrgi replay " + o.capture, out_w, out_h, o.device));
    settings.device.app_device = &view->device();
  } else if (!o.view.screenshot.empty()) {
    throw CommandFailure(2, "--view-screenshot: only with --view");
  }
  std::unique_ptr<Runtime> runtime = take(create_runtime(settings, cameras, scene));

  ReplayMeta meta{o.capture, runtime->technique(), level, level == kAutoLevel ? "auto" : runtime->level_names()[size_t(level)],
                  runtime->device().name, runtime->device().type == "cpu",
                  runtime->memory_mib(), out_w, out_h};
  ReplayOutput output = take(ReplayOutput::create(o.out, meta));
  if (Status st = output.set_images(o.output_images.wants("composite"), o.output_images.wants("overlay")); !st.ok())
    fail_with(st.error());
  if (!o.video.empty()) {
    std::vector<double> stamps;
    for (size_t i = 0; i < frames; ++i) stamps.push_back(capture.entry(i).timestamp);
    output.set_video(take(VideoOutput::create(o.video, out_w, out_h, capture_fps(stamps))));
  }

  // docs/DESIGN.md: poses come from groundtruth.txt when present, else from AprilTag tracking of the
  // colour frames (capture.json "apriltag"). Without either the runtime keeps the last pose.
  std::optional<AprilTagTracker> tracker;
  if (info.apriltag) tracker = take(AprilTagTracker::create(*info.apriltag, info.color));

  Replay replay{o, capture, info, frames, out_w, out_h, env_intensity, runtime.get(), output, tracker};
  replay.view = view.get();
  replay.next_technique = [&]() -> Runtime* {
    const RuntimeSettings next = take(next_technique_settings(settings, runtime->technique()));
    runtime.reset();  // its frames were flushed with the chunk
    runtime = take(create_runtime(next, cameras, scene));
    std::cerr << "mrgi: view: technique " << next.technique << " from frame " << replay.written << "\n";
    return runtime.get();
  };
  replay.t0 = std::chrono::steady_clock::now();
  replay.in_flight.resize(frames);
  const bool preloaded = o.io != "overlapped";
  if (preloaded) replay.run_preloaded();
  else replay.run_overlapped();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - replay.t0).count();
  if (replay.written != frames && !replay.stopped)
    throw CommandFailure(1, "internal: " + std::to_string(replay.written) + " of " + std::to_string(frames) +
                                " frames came back");
  if (replay.stopped) std::cerr << "mrgi: view: stopped after " << replay.written << " of " << frames << " frames\n";
  output.set_achieved({replay.written, seconds,
                       preloaded ? "decode a chunk of frames, process them back to back, encode them (PNG I/O included, "
                                   "never beside a frame)"
                                 : "decode, process and encode every frame, overlapped (PNG I/O included)"});
  if (preloaded)
    output.set_sustained({replay.frames_seconds, replay.frames_cpu_seconds, replay.sustained_frames,
                          settings.frames_in_flight});
  if (!o.quiet)
    std::cerr << "mrgi: replayed " << frames << " frames in " << seconds << " s: "
              << double(frames) / seconds << " fps achieved (decode and encode included)\n";
  nlohmann::json summary = take(output.finish());
  if (tracker)
    std::cerr << "mrgi: AprilTag tracking gave a pose for " << replay.tracked << " frames, none for "
              << replay.untracked << " (capture has no groundtruth.txt pose for them)\n";
  std::cout << replay_line(summary, o.out) << "\n";
  if (view && !o.view.screenshot.empty()) {
    if (Status st = write_png(o.view.screenshot, take(view->screenshot())); !st.ok()) fail_with(st.error());
  } else if (view && !replay.stopped) {
    std::cerr << "mrgi: view: the last frame stays up until the window is closed (Q or Esc)\n";
    view->hold();
  }
}

void setup(CLI::App& app) {
  auto opts = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand("replay", "Replay a capture (format v1) through a technique and write frames, stats and a summary");
  cmd->add_option("capture", opts->capture, "capture folder (capture format v1, TUM RGB-D compatible)")->required();
  opts->quality.add(*cmd);
  cmd->add_option("--out,-o", opts->out, "output folder (frames/, stats.json, summary.json, side_by_side.png)")->required();
  cmd->add_option("--frames,-n", opts->frames, "replay at most N frames (0 = all)")->check(CLI::NonNegativeNumber);
  opts->output_images.add(*cmd);
  cmd->add_option("--video", opts->video,
                  "also write the composited frames as a clip: FILE.png (animated PNG, lossless) or "
                  "FILE.mp4/.mkv/.webm (needs ffmpeg on PATH), at the capture's frame rate");
  cmd->add_option("--width", opts->width, "output width in pixels (default: the colour camera's)")->check(CLI::Range(16, 8192));
  cmd->add_option("--height", opts->height, "output height in pixels")->check(CLI::Range(16, 8192));
  cmd->add_option("--light", opts->light,
                  "declared: scene.json's lamps and environment light the scene (default); estimate: they are "
                  "ignored and the runtime estimates the light from the frames, as for an app that declares none")
      ->check(CLI::IsMember({"declared", "estimate"}));
  cmd->add_option("--dlpv-ablation", opts->dlpv_ablation,
                  "dlpv without one of the paper's ideas (mrgi/research.h DlpvAblation): two-volumes (V^rho and V^mu "
                  "propagated apart, not V^Delta), no-damping (of negative flux), no-shift (VPLs at their surface, not "
                  "half a cell along the normal), no-self-bounce (V^rho from the real "
                  "surfaces' VPLs only, not the virtual objects' own); comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember(ablation_names(kDlpvAblations)));
  cmd->add_option("--specular-ablation", opts->specular_ablation,
                  "mirrors and glass without one of the paper's ideas (mrgi/research.h SpecularAblation), any "
                  "technique: off (shaded by the technique as any material), no-back-projection (real surfaces in "
                  "a mirror or through glass show their rendered light, not the camera's colour), no-depth-test "
                  "(the camera's colour is taken without the depth validity test), no-caustics (spot lamps make no caustics "
                  "through mirrors and glass); comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember(ablation_names(kSpecularAblations)));
  cmd->add_option("--dir-ablation", opts->dir_ablation,
                  "dir without one of the paper's ideas (mrgi/research.h DirAblation): one-shadow-map (one shadow map a "
                  "lamp and one ISM a VPL with the nearest caster and its kind, not one each), no-real-only-vpls (no ir(VPL): the real bounce "
                  "a virtual object blocks stays in L_r), one-bounce (no bounce light source: the lamps' VPLs only, "
                  "at the levels with multiple bounces), no-environment-vpls (the environment light baseline leaves "
                  "unshadowed stays unshadowed), no-temporal-smoothing (each frame's VPL light alone), no-caustic-vpls (VPLs drawn "
                  "on mirrors and glass stay there instead of moving to where their light lands); comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember(ablation_names(kDirAblations)));
  cmd->add_option("--device", opts->device, "Vulkan device: index, cpu / lavapipe, gpu, or name part (default $MRGI_DEVICE, else lavapipe)");
  cmd->add_flag("--validate", opts->validate, "enable Vulkan validation layers");
  opts->view.add(*cmd, "as it is written (frames one at a time)", "after the last frame");
  cmd->add_flag("--profile", opts->profile,
                "profiling mode: each pass submitted alone and host-timed, so stats.json's per-pass times add up "
                "to the frame on any device (without it, a CPU device's GPU timestamps do not time passes); "
                "frames run slower");
  cmd->add_flag("--vulkan-1-2", opts->vulkan_1_2,
                "use the Vulkan 1.2 path on a 1.3 device (synchronization2 and dynamic rendering from their KHR "
                "extensions, as a 1.2 driver runs them)");
  cmd->add_flag("--no-residual-light", opts->no_residual_light,
                "with declared lamps: light by the lamps alone, without the estimate of the real light they do not "
                "explain (RuntimeSettings::residual_light; an ablation)");
  cmd->add_flag("--no-albedo-fit", opts->no_albedo_fit,
                "the probeless estimate with the grey-world albedo (0.5), not the surfaces' albedo measured from their "
                "interreflection (RuntimeSettings::light_albedo_fit false; the comparison)");
  cmd->add_flag("--no-near-field", opts->no_near_field,
                "the probeless estimate with the seen surfaces' bounce read as part of the distant light, not computed "
                "from them and added at the objects (RuntimeSettings::light_near_field false; the comparison)");
  cmd->add_flag("--no-distant-views", opts->no_distant_views,
                "the probeless estimate from surfaces only: regions without depth (sky, windows, beyond the sensor's "
                "range) not read as the distant light (RuntimeSettings::light_distant_views false; the comparison)");
  cmd->add_flag("--single-view-light", opts->single_view_light,
                "the probeless estimate from each view on its own, not from every view seen "
                "(RuntimeSettings::light_accumulate_views false; the comparison)");
  cmd->add_option("--io", opts->io,
                  "preloaded (default): decode a chunk of frames, run them back to back, then write them, so the "
                  "frames have the cores to themselves as on a live device, the scheduler holds their own cost to "
                  "the budget and the headline sustained ms is measured; overlapped: decode and write on their own "
                  "threads beside the frames (faster end to end on many cores; no sustained ms)")
      ->check(CLI::IsMember({"preloaded", "overlapped"}));
  cmd->add_option("--preload-frames", opts->preload_frames,
                  "--io preloaded: frames decoded ahead at a time (default: as many as fit in 512 MiB, about 130 "
                  "at 640x480)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet,-q", opts->quiet, "no progress on stderr");
  cmd->callback([opts] { run_replay(*opts); });
}

}  // namespace

MRGI_COMMAND(replay, setup);

}  // namespace mrgi::tool
