// mrgi lpv-costs: the light propagation volume's cost tables beside the DLPV paper's Tables 2
// and 3 (perf/include/mrgi/perf/lpv_costs.h).
#include <iostream>

#include "commands.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/lpv_costs.h"

namespace mrgi::tool {
namespace {

struct Options {
  perf::LpvCostSettings settings;
  std::string out;
};

void run(const Options& o) {
  perf::ensure_lp_num_threads();  // before any Vulkan instance: lavapipe reads it then
  const perf::LpvCosts c = take(perf::measure_lpv_costs(o.settings, progress_since_now()));
  const std::string md = perf::lpv_costs_markdown(c);
  std::cout << md;
  if (!o.out.empty()) write_text_file(o.out, md);
}

void setup(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "lpv-costs", "Time the light propagation volume (propagation by volume size and steps, injection by "
                   "RSM size) beside the DLPV paper's Tables 3 and 2");
  cmd->add_option("--sizes", o->settings.volume_sizes, "volume sizes, cells per side (each divides the largest)");
  cmd->add_option("--steps", o->settings.steps, "propagation steps");
  cmd->add_option("--rsm", o->settings.rsm_sizes, "RSM sizes, texels per side");
  cmd->add_option("--repeats", o->settings.repeats, "timed runs per entry (median reported)")->check(CLI::Range(1, 100));
  cmd->add_option("--device", o->settings.device.device, "Vulkan device: index, cpu / lavapipe, gpu, or name part (default lavapipe)");
  cmd->add_option("-o,--out", o->out, "also write the Markdown tables to this file");
  cmd->callback([o] { run(*o); });
}

}  // namespace

MRGI_COMMAND(lpv_costs, setup);

}  // namespace mrgi::tool
