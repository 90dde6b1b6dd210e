// mrgi synth DESCRIPTION --out CAPTURE: renders a synthetic capture (camera, depth, env camera,
// ground-truth references) from a scene description with the path-traced reference.
#include <cstdio>
#include <optional>
#include <string>

#include "commands.h"
#include "mrgi/reference/description.h"
#include "mrgi/reference/synth.h"

namespace mrgi::tool {
namespace {

struct SynthArgs {
  std::string description, out;
  std::optional<int> frames, spp, width, height, threads;
  std::optional<uint64_t> seed, noise_floor_seed;
  std::string reference_format = "delta";
  std::string from_renders;
  bool resume = false;
  std::optional<int> stop_after;
};

void run_synth(const SynthArgs& a) {
  auto description = take(reference::load_scene_description(a.description));
  reference::SynthOptions options;
  options.out = a.out;
  options.frames = a.frames;
  options.spp = a.spp;
  options.width = a.width;
  options.height = a.height;
  options.seed = a.seed;
  options.threads = a.threads.value_or(0);
  options.noise_floor_seed = a.noise_floor_seed;
  options.resume = a.resume;
  options.from_renders = a.from_renders;
  options.stop_after = a.stop_after;
  options.references = a.reference_format == "plain" ? ReferenceStorage::Plain : ReferenceStorage::Delta;
  options.progress = [](const std::string& what, size_t done, size_t total, double elapsed) {
    progress(what, done, total, elapsed);
  };
  const auto report = take(reference::synthesize_capture(description, options));
  if (!report.finished) {
    std::fprintf(stderr,
                 "synth: stopped after %d frames (%d of %d done, %.1f s; %.1f s rendering over all runs); "
                 "%s.partial holds them: run the same command with --resume to go on\n",
                 report.frames_rendered, report.frames_resumed + report.frames_rendered, report.frames,
                 report.seconds, report.frame_seconds, a.out.c_str());
  } else {
    const std::string spp = report.spp ? std::to_string(report.spp) + " spp" : "frames from " + a.from_renders;
    std::fprintf(stderr, "synth: wrote %s: %d frames (%d resumed), %s, %.1f s (%.1f s rendering over all runs)%s\n",
                 a.out.c_str(), report.frames, report.frames_resumed, spp.c_str(), report.seconds,
                 report.frame_seconds, report.dropped_samples ? " (non-finite samples were dropped)" : "");
  }
  if (report.noise_floor)
    std::printf("reference noise floor (frame 0, RDE vs an independent render): all %.4f real %.4f virtual %.4f; "
                "delta rms %.5f\n",
                report.noise_floor->rde_all, report.noise_floor->rde_real, report.noise_floor->rde_virtual,
                report.noise_floor->delta_rms);
  if (report.dropped_samples)
    std::fprintf(stderr, "synth: %zu non-finite samples dropped\n", report.dropped_samples);
}

void setup(CLI::App& app) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* cmd = app.add_subcommand(
      "synth", "Render a synthetic capture (capture format v1 with references) from a scene description");
  cmd->add_option("description", args->description, "scene description JSON (tools/reference/include/mrgi/reference/description.h)")
      ->required();
  cmd->add_option("--out", args->out, "capture folder to create (must not exist)")->required();
  cmd->add_option("--frames", args->frames, "number of frames (overrides the description)")->check(CLI::Range(1, 100000));
  cmd->add_option("--spp", args->spp, "samples per pixel (overrides the description)")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--seed", args->seed, "random seed (overrides the description)");
  cmd->add_option("--width", args->width, "image width; intrinsics are scaled")->check(CLI::Range(1, 8192));
  cmd->add_option("--height", args->height, "image height; intrinsics are scaled")->check(CLI::Range(1, 8192));
  cmd->add_option("--noise-floor-seed", args->noise_floor_seed,
                  "also render frame 0 with this seed and print the reference noise floor (RDE)");
  cmd->add_option("--reference-format", args->reference_format,
                  "how references are stored: delta (reference/NNNNNN.delta.png, (reference - rgb) mod 256, "
                  "lossless and smaller; default) or plain (reference/NNNNNN.png)")
      ->check(CLI::IsMember({"delta", "plain"}));
  cmd->add_flag("--resume", args->resume,
               "keep the frames an interrupted run left in OUT.partial (same description, inputs and settings, "
               "else refused) and render only the missing ones; starts from frame 0 when there is none");
  cmd->add_option("--stop-after", args->stop_after,
                  "render at most N frames in this run, then stop, leaving OUT.partial for --resume")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--from-renders", args->from_renders,
                  "take the frames from another renderer's EXR images of the same description instead of "
                  "path-tracing them (tools/cycles/render_description.py writes them; layout in "
                  "tools/reference/src/synth_from_renders.h)");
  cmd->add_option("--threads", args->threads, "render threads (default: all cores)")->check(CLI::Range(1, 256));
  cmd->callback([args] { run_synth(*args); });
}

}  // namespace
MRGI_COMMAND(synth, setup);
}  // namespace mrgi::tool
