// What `mrgi bench --out DIR` writes, all under DIR.partial and renamed to DIR at the end:
//   bench.json  everything: settings, device, lp_num_threads, commit, floors, every entry with
//               frame and per-pass median/p95 (ms and ratio), memory, error (all/real/virtual:
//               RDE, delta RMS, RMSE, SSIM), suite aggregates per level, the Pareto front and
//               the regression check when one was asked for
//   bench.csv   one row per scene/technique/level
//   report.md   per technique a table per level and scene, the error by region and effect, the
//               floors, the plots
//   passes.md   every level's passes (pass_table_markdown)
//   passes.png  each level's passes, stacked (render_pass_plot)
//   pareto.png  sustained ms against RDE per technique level (suite aggregate), fronts marked
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "mrgi/expected.h"
#include "mrgi/image.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/regression.h"

namespace mrgi::perf {

nlohmann::json bench_json(const BenchResult& result, const CheckReport* check);
// An error report as JSON, the form bench.json and mrgi replay's stats and summary share: per
// pixel set (all, real, virtual, influenced, rest, darkened, brightened) its RDE (null when
// undefined), delta RMS, RMSE, SSIM, pixels and the signed change sums, total and per channel.
nlohmann::json error_figures_json(const ErrorFigures& f);
nlohmann::json error_report_json(const RdeReport& r);
std::string bench_csv(const BenchResult& result);
std::string report_markdown(const BenchResult& result, const CheckReport* check);
// 1640 x 600 plot of the suite aggregates (aggregate_levels): RDE over all, real and virtual pixels
// against sustained ms, one colour and marker per technique.
ImageRGB8 render_pareto_plot(const BenchResult& result);
// 1480 x (bars) plot of each level's profiled passes, stacked, each bar on its own scale
// (perf/src/pass_plot.cpp says what is drawn).
ImageRGB8 render_pass_plot(const BenchResult& result);
// passes.md: every level's passes (median, p95, ratio to the floor, CPU ms), by technique.
std::string pass_table_markdown(const BenchResult& r);

// Writes the four files. DIR must be absent, empty or an earlier bench output (has bench.json).
Status write_bench_outputs(const std::string& dir, const BenchResult& result, const CheckReport* check);

// Cost scaling (`mrgi bench --sizes`): one run of the same scenes, techniques and levels per
// output size, smallest first. Per technique level (mean over scenes): sustained ms at each
// size, ms per megapixel, and how cost grew against pixels (1.0 = in proportion).
std::string scaling_markdown(const std::vector<BenchResult>& by_size);
nlohmann::json scaling_json(const std::vector<BenchResult>& by_size);

}  // namespace mrgi::perf
