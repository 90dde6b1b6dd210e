// mrgi loadtest: the scheduler under a changing load (mrgi/perf/load_test.h), report and plot.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/load_test.h"
#include "mrgi/platform/output_dir.h"

namespace mrgi::tool {
namespace {

struct LoadTestOptions {
  perf::LoadTestSettings settings;
  std::string out;
  bool quiet = false, no_oracle = false;
};

void run_loadtest(LoadTestOptions& o) {
  perf::ensure_lp_num_threads();
  o.settings.oracle = !o.no_oracle;
  // Each run (the scheduled one, then one per fixed level for the oracle) has its own clock.
  auto t0 = std::chrono::steady_clock::now();
  if (!o.quiet) o.settings.progress = [t0](const std::string& what, size_t done, size_t total, double) mutable {
    if (done == 1) t0 = std::chrono::steady_clock::now();
    if (done % 30 == 0 || done == total)
      progress(what, done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  };
  perf::LoadTestResult r = take(perf::run_load_test(o.settings));
  OutputDir out = take(OutputDir::begin(o.out, "--out"));
  const std::string md = perf::load_test_markdown(r);
  std::ofstream(out.partial() + "/report.md") << md;
  if (Status st = write_png(out.partial() + "/trace.png", perf::render_load_trace(r)); !st.ok()) fail_with(st.error());
  nlohmann::json j;
  j["device"] = r.device;
  j["technique"] = o.settings.technique;
  j["scene"] = o.settings.scene;
  j["budget_ms"] = o.settings.budget_ms;
  j["share_within"] = r.share_within;
  j["switches_per_s"] = r.switches_per_s;
  j["mean_level"] = r.mean_level;
  j["mean_oracle_level"] = r.mean_oracle_level;
  j["mean_scale"] = r.mean_scale;
  nlohmann::json frames = nlohmann::json::array();
  for (size_t k = 0; k < r.scheduled.size(); ++k)
    frames.push_back({{"level", r.scheduled[k].level}, {"scale", r.scheduled[k].scale}, {"cost_ms", r.scheduled[k].cost_ms},
                      {"technique_ran", r.scheduled[k].technique_ran},
                      {"oracle_level", r.oracle_level.empty() ? -1 : r.oracle_level[k]}});
  j["frames"] = frames;
  std::ofstream(out.partial() + "/load.json") << j.dump(1) << "\n";
  if (Status st = out.commit(); !st.ok()) fail_with(st.error());
  std::cout << md;
}

void setup(CLI::App& app) {
  auto o = std::make_shared<LoadTestOptions>();
  o->settings.suite = "perf/suite.json";
  CLI::App* cmd = app.add_subcommand("loadtest", "The frame-budget scheduler under a changing load: report, trace plot, figures");
  cmd->add_option("--suite", o->settings.suite, "suite manifest (JSON)")->capture_default_str();
  cmd->add_option("--scene,-s", o->settings.scene, "suite scene (with a virtual object and a lamp)")->capture_default_str();
  cmd->add_option("--technique,-t", o->settings.technique, "technique")->capture_default_str();
  cmd->add_option("--budget-ms", o->settings.budget_ms, "frame budget, ms")->capture_default_str()->check(frame_budget_ms_check());
  cmd->add_option("--frames,-n", o->settings.frames, "frames in the run (>= 60)")->capture_default_str()->check(CLI::Range(60, 100000));
  cmd->add_flag("--no-oracle", o->no_oracle, "skip the fixed-level runs the oracle needs");
  cmd->add_option("--device", o->settings.device.device, "Vulkan device: index, cpu / lavapipe, gpu, or name part");
  cmd->add_option("--out,-o", o->out, "output folder (report.md, trace.png, load.json)")->required();
  cmd->add_flag("--quiet,-q", o->quiet, "no progress on stderr");
  cmd->callback([o] { run_loadtest(*o); });
}

}  // namespace

MRGI_COMMAND(loadtest, setup);

}  // namespace mrgi::tool
