// mrgi peaks: this machine's multiply-add throughput, copy bandwidth and scattered image-load
// rate as a Vulkan compute device (perf/include/mrgi/perf/peaks.h), beside the floor pass, in
// Markdown on stdout (or JSON with --json); --out writes the Markdown to a file as well.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/peaks.h"

namespace mrgi::tool {
namespace {

struct PeaksOptions {
  perf::PeaksSettings settings;
  bool json = false;
  std::string out;
};

void run_peaks(const PeaksOptions& o) {
  perf::ensure_lp_num_threads();  // before any Vulkan instance: lavapipe reads it then
  const perf::Peaks p = take(perf::measure_peaks(o.settings));
  const std::string md = perf::peaks_markdown(p);
  if (!o.out.empty()) write_text_file(o.out, md);
  if (!o.json) {
    std::cout << md;
    return;
  }
  nlohmann::json j{{"device", p.device}, {"driver", p.driver}, {"lp_num_threads", p.lp_num_threads},
                   {"floor_median_ms", p.floor_median_ms}, {"results", nlohmann::json::array()}};
  for (const perf::PeakResult& r : p.results)
    j["results"].push_back({{"name", r.name}, {"median_ms", r.median_ms}, {"min_ms", r.min_ms},
                            {"work", r.work}, {"unit", r.unit}, {"rate", r.rate},
                            {"best_rate", r.best_rate}});
  std::cout << j.dump(2) << "\n";
}

void setup(CLI::App& app) {
  auto opts = std::make_shared<PeaksOptions>();
  CLI::App* cmd = app.add_subcommand(
      "peaks", "Measure this device's FMA throughput, copy bandwidth and scattered image-load "
               "rate beside the floor pass (the peaks that bound a pass's time)");
  cmd->add_option("--repeats", opts->settings.repeats, "timed runs per kernel (median reported)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--device", opts->settings.device.device,
                  "Vulkan device: index, cpu / lavapipe, gpu, or name part (default $MRGI_DEVICE, else lavapipe)");
  cmd->add_flag("--json", opts->json, "JSON on stdout instead of Markdown");
  cmd->add_option("-o,--out", opts->out, "also write the Markdown table to this file");
  cmd->callback([opts] { run_peaks(*opts); });
}

}  // namespace

MRGI_COMMAND(peaks, setup);

}  // namespace mrgi::tool
