// mrgi light-family: the light-estimation family (perf/suite/light/family.json) replayed lit by
// its true light and by the runtime's estimate; a Markdown table of direction, irradiance,
// colour and RDE figures per scene and per half (tuning / held out), and JSON beside it.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "commands.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/light_family.h"

namespace mrgi::tool {
namespace {

struct Options {
  perf::LightFamilySettings settings;
  std::string level = "0";
  std::string out;
};

void run(Options o) {
  perf::ensure_lp_num_threads();
  o.settings.level = resolve_level(o.settings.technique, o.level);
  const auto results = take(perf::run_light_family(o.settings, progress_since_now()));
  const std::string md = perf::light_family_markdown(results, o.settings);
  std::cout << md;
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    write_text_file(o.out + "/light-family.md", md);
    write_text_file(o.out + "/light-family.json", perf::light_family_json(results));
  }
}

void setup(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "light-family", "Replay the light-estimation family lit by the true light and by the runtime's "
                      "estimate; direction, irradiance, colour and RDE figures per scene and per half");
  cmd->add_option("--manifest", o->settings.manifest, "family manifest (default perf/suite/light/family.json)");
  cmd->add_option("--technique", o->settings.technique, "technique to light (default baseline)");
  cmd->add_option("--level", o->level, "level: number, name or 'last' (default 0)");
  cmd->add_option("--root", o->settings.root, "folder the manifest's capture paths are relative to (default .)");
  cmd->add_option("--half", o->settings.half,
                  "all (default), tuning (the scenes a parameter may be chosen on) or held-out")
      ->check(CLI::IsMember({"all", "tuning", "held-out"}));
  cmd->add_flag("--single-view", [o](int64_t n) { o->settings.accumulate_views = n == 0; },
                "solve each view on its own (RuntimeSettings::light_accumulate_views false; the comparison)");
  cmd->add_flag("--no-near-lamps", [o](int64_t n) { o->settings.near_lamps = n == 0; },
                "distant light only: no near lamp looked for among the views (RuntimeSettings::light_near_lamps false)");
  cmd->add_flag("--no-albedo-fit", [o](int64_t n) { o->settings.albedo_fit = n == 0; },
                "the grey-world albedo (0.5): the surfaces' albedo not measured from their interreflection (RuntimeSettings::light_albedo_fit false)");
  cmd->add_flag("--no-near-field", [o](int64_t n) { o->settings.near_field = n == 0; },
                "the bounce of the seen surfaces read as part of the distant light, not computed from them and added at the objects (RuntimeSettings::light_near_field false)");
  cmd->add_flag("--no-distant-views", [o](int64_t n) { o->settings.distant_views = n == 0; },
                "surfaces only: regions without depth (sky, windows, beyond the sensor's range) not read as the distant light (RuntimeSettings::light_distant_views false)");
  cmd->add_flag("--validate", o->settings.validate, "Vulkan validation layers on (a message fails the run)");
  cmd->add_option("-o,--out", o->out, "write light-family.md and light-family.json into this folder");
  cmd->callback([o] { run(*o); });
}

}  // namespace

MRGI_COMMAND(light_family, setup);

}  // namespace mrgi::tool
