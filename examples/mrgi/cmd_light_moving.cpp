// mrgi light-moving: the moving-camera light family (perf/suite/light/moving/family.json): each
// 90-degree sweep replayed lit by its true light and by the runtime's probeless estimate, the
// estimate's figures as the sweep grows; the light-switch captures (how many frames until the
// estimate follows a lamp switched on) and, on request, a long back-and-forth loop for drift.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/light_moving.h"

namespace mrgi::tool {
namespace {

struct Options {
  perf::MovingFamilySettings settings;
  std::string level = "0";
  std::string out;
  bool single_view = false, no_switches = false;
};

void run(Options o) {
  perf::ensure_lp_num_threads();
  o.settings.family.level = resolve_level(o.settings.family.technique, o.level);
  o.settings.family.accumulate_views = !o.single_view;
  o.settings.switches = !o.no_switches;
  const auto report = take(perf::run_moving_family(o.settings, progress_since_now()));
  const std::string md = perf::moving_family_markdown(report, o.settings);
  std::cout << md;
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    write_text_file(o.out + "/light-moving.md", md);
    write_text_file(o.out + "/light-moving.json", perf::moving_family_json(report));
  }
}

void setup(CLI::App& app) {
  auto o = std::make_shared<Options>();
  o->settings.family.manifest = "perf/suite/light/moving/family.json";
  CLI::App* cmd = app.add_subcommand(
      "light-moving", "Replay the moving-camera light family (render it first: bash "
                      "perf/suite/light/render_moving_family.sh); the estimate's figures as the sweep grows, "
                      "lamp switches followed, drift over a long loop");
  cmd->add_option("--manifest", o->settings.family.manifest, "family manifest (default perf/suite/light/moving/family.json)");
  cmd->add_option("--technique", o->settings.family.technique, "technique to light (default baseline)");
  cmd->add_option("--level", o->level, "level: number, name or 'last' (default 0)");
  cmd->add_option("--root", o->settings.family.root, "folder the manifest's capture paths are relative to (default .)");
  cmd->add_option("--half", o->settings.family.half,
                  "all (default), tuning (the scenes a parameter may be chosen on) or held-out")
      ->check(CLI::IsMember({"all", "tuning", "held-out"}));
  cmd->add_flag("--single-view", o->single_view,
                "solve each view on its own (RuntimeSettings::light_accumulate_views false; the comparison)");
  cmd->add_flag("--no-switches", o->no_switches, "leave the lamp-switch captures out");
  cmd->add_option("--drift-frames", o->settings.drift_frames,
                  "also play one scene back and forth this many frames and report the estimate's drift (0: no)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--drift-scene", o->settings.drift_scene, "the scene the drift run loops (default the half's first)");
  cmd->add_flag("--no-near-lamps", [o](int64_t n) { o->settings.family.near_lamps = n == 0; },
                "distant light only: no near lamp looked for among the views (RuntimeSettings::light_near_lamps false)");
  cmd->add_flag("--no-albedo-fit", [o](int64_t n) { o->settings.family.albedo_fit = n == 0; },
                "the grey-world albedo (0.5): the surfaces' albedo not measured from their interreflection (RuntimeSettings::light_albedo_fit false)");
  cmd->add_flag("--no-near-field", [o](int64_t n) { o->settings.family.near_field = n == 0; },
                "the bounce of the seen surfaces read as part of the distant light, not computed from them and added at the objects (RuntimeSettings::light_near_field false)");
  cmd->add_flag("--no-distant-views", [o](int64_t n) { o->settings.family.distant_views = n == 0; },
                "surfaces only: regions without depth (sky, windows, beyond the sensor's range) not read as the distant light (RuntimeSettings::light_distant_views false)");
  cmd->add_flag("--validate", o->settings.family.validate, "Vulkan validation layers on (a message fails the run)");
  cmd->add_option("-o,--out", o->out, "write light-moving.md and light-moving.json into this folder");
  cmd->callback([o] { run(*o); });
}

}  // namespace

MRGI_COMMAND(light_moving, setup);

}  // namespace mrgi::tool
