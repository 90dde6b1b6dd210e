// bench.json, bench.csv and report.md, and writing all four outputs atomically.
#include "mrgi/platform/output_dir.h"
#include "mrgi/perf/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "mrgi/perf/pareto.h"
#include "mrgi/perf/sample_sheet.h"
#include "mrgi/perf/stats.h"

namespace fs = std::filesystem;

namespace mrgi::perf {
namespace {

nlohmann::json time_json(const TimeSummary& t) {
  return {{"samples", t.samples},          {"median_ms", t.median_ms},     {"p95_ms", t.p95_ms},
          {"median_ratio", t.median_ratio}, {"p95_ratio", t.p95_ratio},  {"min_ms", t.min_ms},
          {"min_ratio", t.min_ratio}};
}

nlohmann::json error_json(bool has_reference, const RdeReport& r) {
  if (!has_reference) return nullptr;
  return error_report_json(r);
}

std::string fmt(double v, int decimals) {
  if (!std::isfinite(v)) return "nan";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// An RDE cell: "-" when there is no reference or the RDE is undefined over that set.
// The frame-to-frame change of the delta on static real pixels, linear x 1000, output / truth.
std::string stability_cell(const BenchEntry& e) {
  if (e.stability_pairs == 0) return "-";
  return fmt(1000.0 * e.stability, 2) + (e.truth_stability >= 0.0 ? " / " + fmt(1000.0 * e.truth_stability, 2) : "");
}

std::string rde_cell(bool has_reference, const ErrorFigures& f) {
  return has_reference && f.rde_defined ? fmt(f.rde, 3) : "-";
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<size_t> front_of(const std::vector<LevelAggregate>& levels, std::vector<size_t>* plotted) {
  std::vector<ParetoPoint> points;
  for (size_t i = 0; i < levels.size(); ++i)
    if (levels[i].has_reference && levels[i].error.all.rde_defined) {
      points.push_back({levels[i].mean_median_ms, levels[i].error.all.rde});
      plotted->push_back(i);
    }
  std::vector<size_t> front;
  for (size_t k : pareto_front(points)) front.push_back((*plotted)[k]);
  return front;
}

Status write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  if (!f) return fail(ErrorKind::Device, path + ": cannot open for writing");
  f << text;
  if (!f) return fail(ErrorKind::Device, path + ": write failed");
  return ok_status();
}

// With scenes from more than one manifest: per set and technique level, the median over its
// scenes of each scene's RDE (pooled over its frames) and the worst scene, so a set made by
// another renderer (perf/cycles-*.json) reads beside the suite instead of inside its mean.
std::string accuracy_by_set(const BenchResult& r) {
  std::vector<std::string> sets;
  for (const BenchEntry& e : r.entries)
    if (std::find(sets.begin(), sets.end(), e.set) == sets.end()) sets.push_back(e.set);
  if (sets.size() < 2) return "";
  std::ostringstream o;
  o << "## Accuracy by scene set\n\nMedian over each set's scenes of the scene's RDE (its measured frames pooled), "
       "and the set's worst scene by all-pixel RDE:\n\n"
       "| set | technique | level | scenes | RDE all | RDE real | RDE virtual | worst scene (all) |\n"
       "|---|---|---|---:|---:|---:|---:|---|\n";
  for (const std::string& set : sets) {
    std::vector<std::pair<std::string, int>> levels;  // technique, level, in first-seen order
    for (const BenchEntry& e : r.entries)
      if (e.set == set && e.has_reference &&
          std::find(levels.begin(), levels.end(), std::make_pair(e.technique, e.level)) == levels.end())
        levels.emplace_back(e.technique, e.level);
    for (const auto& [technique, level] : levels) {
      std::vector<double> all, real, virt;
      std::string name, worst;
      double worst_rde = -1.0;
      for (const BenchEntry& e : r.entries) {
        if (e.set != set || e.technique != technique || e.level != level || !e.has_reference) continue;
        name = e.level_name;
        if (e.error.all.rde_defined) {
          all.push_back(e.error.all.rde);
          if (e.error.all.rde > worst_rde) {
            worst_rde = e.error.all.rde;
            worst = e.scene;
          }
        }
        if (e.error.real.rde_defined) real.push_back(e.error.real.rde);
        if (e.error.virtual_.rde_defined) virt.push_back(e.error.virtual_.rde);
      }
      auto med = [](const std::vector<double>& v) { return v.empty() ? std::string("-") : fmt(median(v), 3); };
      o << "| " << set << " | " << technique << " | " << level << " " << name << " | " << all.size() << " | "
        << med(all) << " | " << med(real) << " | " << med(virt) << " | "
        << (worst.empty() ? std::string("-") : worst + " " + fmt(worst_rde, 3)) << " |\n";
    }
  }
  o << "\n";
  return o.str();
}

}  // namespace

nlohmann::json error_figures_json(const ErrorFigures& f) {
  return {{"rde", f.rde_defined ? nlohmann::json(f.rde) : nlohmann::json(nullptr)},
          {"delta_rms", f.delta_rms},
          {"rmse8", f.rmse8},
          {"ssim", f.ssim},
          {"pixels", f.pixels},
          {"change_sum", f.change_sum},
          {"truth_change_sum", f.truth_change_sum},
          {"change_rgb", {f.change_rgb[0], f.change_rgb[1], f.change_rgb[2]}},
          {"truth_change_rgb", {f.truth_change_rgb[0], f.truth_change_rgb[1], f.truth_change_rgb[2]}}};
}

nlohmann::json error_report_json(const RdeReport& r) {
  return {{"all", error_figures_json(r.all)},
          {"real", error_figures_json(r.real)},
          {"virtual", error_figures_json(r.virtual_)},
          {"influenced", error_figures_json(r.influenced)},
          {"rest", error_figures_json(r.rest)},
          {"darkened", error_figures_json(r.darkened)},
          {"brightened", error_figures_json(r.brightened)},
          {"silhouette", error_figures_json(r.silhouette)}};
}

nlohmann::json bench_json(const BenchResult& r, const CheckReport* check) {
  nlohmann::json j;
  j["version"] = 1;
  j["started_utc"] = r.started_utc;
  j["duration_s"] = r.duration_s;
  j["suite"] = r.suite;
  j["subset"] = r.subset;
  j["frames"] = r.frames;
  j["warmup"] = r.warmup;
  j["device"] = r.device;
  j["driver"] = r.driver;
  j["lp_num_threads"] = r.lp_num_threads;
  j["commit"] = r.commit.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.commit);
  j["dirty"] = r.dirty;
  j["time_is"] = "GPU time from the frame graph's timestamps; ratio = ms / the scene's floor median ms";
  j["floor_median_ms"] = r.floor_median_ms;
  nlohmann::json floors = nlohmann::json::array();
  for (const SceneFloor& f : r.floors)
    floors.push_back({{"scene", f.scene}, {"width", f.width}, {"height", f.height}, {"samples", f.samples},
                      {"median_ms", f.median_ms}, {"p95_ms", f.p95_ms}, {"min_ms", f.min_ms}});
  j["floors"] = floors;
  nlohmann::json entries = nlohmann::json::array();
  for (const BenchEntry& e : r.entries) {
    nlohmann::json passes = nlohmann::json::array();
    for (const PassSummary& p : e.passes) {
      nlohmann::json pj = time_json(p.time);
      pj["name"] = p.name;
      pj["cpu_median_ms"] = p.cpu_median_ms;
      passes.push_back(pj);
    }
    entries.push_back({{"scene", e.scene},
                       {"set", e.set},
                       {"technique", e.technique},
                       {"level", e.level},
                       {"level_name", e.level_name},
                       {"width", e.width},
                       {"height", e.height},
                       {"sustained_ms", e.sustained_ms},
                       {"sustained_ratio", e.sustained_ratio},
                       {"cpu_ms", e.cpu_ms},
                       {"frame_intervals", time_json(e.frame)},
                       {"profiled", time_json(e.profiled)},
                       {"split_over_sustained", e.sustained_ms > 0.0 ? e.profiled.median_ms / e.sustained_ms : 0.0},
                       {"passes", passes},
                       {"memory_mib", e.memory_mib},
                       {"error", error_json(e.has_reference, e.error)},
                       {"stability", {{"pairs", e.stability_pairs},
                                      {"output", e.stability_pairs > 0 ? nlohmann::json(e.stability) : nlohmann::json(nullptr)},
                                      {"truth", e.stability_pairs > 0 && e.truth_stability >= 0.0
                                                    ? nlohmann::json(e.truth_stability)
                                                    : nlohmann::json(nullptr)}}},
                       {"skipped", e.skipped}});
  }
  j["entries"] = entries;
  const std::vector<LevelAggregate> levels = aggregate_levels(r);
  std::vector<size_t> plotted;
  const std::vector<size_t> front = front_of(levels, &plotted);
  nlohmann::json agg = nlohmann::json::array();
  for (size_t i = 0; i < levels.size(); ++i) {
    const LevelAggregate& l = levels[i];
    agg.push_back({{"technique", l.technique},
                   {"level", l.level},
                   {"level_name", l.level_name},
                   {"scenes", l.scenes},
                   {"mean_sustained_ms", l.mean_median_ms},
                   {"mean_sustained_ratio", l.mean_median_ratio},
                   {"mean_cpu_ms", l.mean_cpu_ms},
                   {"max_memory_mib", l.max_memory_mib},
                   {"error", error_json(l.has_reference, l.error)},
                   {"pareto", std::find(front.begin(), front.end(), i) != front.end()}});
  }
  j["suite_aggregate"] = agg;
  if (check) {
    j["check"] = {{"passed", check->passed},
                  {"compared", check->compared},
                  {"violations", check->violations},
                  {"missing_in_run", check->missing_in_run},
                  {"missing_in_baseline", check->missing_in_baseline}};
  }
  return j;
}

std::string bench_csv(const BenchResult& r) {
  // Pass columns: the union of pass names, in first-seen order.
  std::vector<std::string> pass_names;
  std::set<std::string> seen;
  for (const BenchEntry& e : r.entries)
    for (const PassSummary& p : e.passes)
      if (seen.insert(p.name).second) pass_names.push_back(p.name);
  std::ostringstream o;
  o << "scene,technique,level,level_name,width,height,frames,sustained_ms,sustained_ratio,interval_p95_ms,"
       "profiled_median_ms,floor_ms,"
       "memory_mib,rde_all,rde_real,rde_virtual,rde_silhouette,delta_rms,rmse8,ssim";
  for (const std::string& p : pass_names)
    o << "," << csv_field("pass_" + p + "_median_ms") << "," << csv_field("pass_" + p + "_p95_ms") << ","
      << csv_field("pass_" + p + "_median_ratio");
  o << "\n";
  std::map<std::string, double> floor_of;
  for (const SceneFloor& f : r.floors) floor_of[f.scene] = f.median_ms;
  auto rde = [](const BenchEntry& e, const ErrorFigures& f) {
    return e.has_reference && f.rde_defined ? fmt(f.rde, 6) : std::string();
  };
  for (const BenchEntry& e : r.entries) {
    o << csv_field(e.scene) << "," << csv_field(e.technique) << "," << e.level << "," << csv_field(e.level_name)
      << "," << e.width << "," << e.height << "," << e.frame.samples << "," << fmt(e.sustained_ms, 4) << ","
      << fmt(e.sustained_ratio, 4) << "," << fmt(e.frame.p95_ms, 4) << "," << fmt(e.profiled.median_ms, 4) << ","
      << fmt(floor_of[e.scene], 4) << "," << fmt(e.memory_mib, 2) << "," << rde(e, e.error.all) << ","
      << rde(e, e.error.real) << "," << rde(e, e.error.virtual_) << "," << rde(e, e.error.silhouette) << ","
      << (e.has_reference ? fmt(e.error.all.delta_rms, 6) : "") << ","
      << (e.has_reference ? fmt(e.error.all.rmse8, 4) : "") << "," << (e.has_reference ? fmt(e.error.all.ssim, 5) : "");
    for (const std::string& name : pass_names) {
      const PassSummary* p = nullptr;
      for (const PassSummary& q : e.passes)
        if (q.name == name) p = &q;
      if (p)
        o << "," << fmt(p->time.median_ms, 4) << "," << fmt(p->time.p95_ms, 4) << "," << fmt(p->time.median_ratio, 4);
      else
        o << ",,,";
    }
    o << "\n";
  }
  return o.str();
}

std::string report_markdown(const BenchResult& r, const CheckReport* check) {
  std::ostringstream o;
  o << "# mrgi bench\n\n";
  o << "| | |\n|---|---|\n";
  o << "| device | " << r.device << " (" << r.driver << ") |\n";
  o << "| LP_NUM_THREADS | " << (r.lp_num_threads.empty() ? "unset" : r.lp_num_threads) << " |\n";
  o << "| commit | " << (r.commit.empty() ? "unknown" : r.commit) << (r.dirty ? " (with uncommitted changes)" : "")
    << " |\n";
  o << "| started | " << r.started_utc << ", " << fmt(r.duration_s, 1) << " s |\n";
  o << "| frames per run | " << r.frames << " measured after " << r.warmup << " warm-up |\n";
  o << "| floor pass | " << fmt(r.floor_median_ms, 3) << " ms median over every floor sample |\n\n";
  o << "*sustained ms* is the headline: wall clock per frame with every input preloaded and "
       "frames fed back to back, 2 in flight (what a live device sees), from the completion of the last warm-up "
       "frame to that of the last measured one; *p95* is the 95th percentile of the intervals between frame "
       "completions; *ratio* is sustained ms over the scene's floor-pass median, measured in the same process "
       "before each run and between profiled frames. *split* is the median frame of the profiling phase (each pass "
       "submitted alone and host-timed, so its passes add up) over sustained ms. *CPU ms* is the process's CPU time "
       "(host thread and driver workers) over the same frames, per frame: on a shared machine it moves less with "
       "other tenants' load than wall time, so compare builds by it. RDE is pooled over the measured frames (0 = perfect, 1 = no better than the camera "
       "frame; `-` = undefined: no reference, or nothing should change in that set of pixels). RMSE in 8-bit "
       "units and SSIM are over all pixels. *flicker* is the frame-to-frame change of the output's delta (output - "
       "camera) on real surfaces that did not move, mean per pixel and channel, linear x 1000, over consecutive "
       "measured frames, beside the truth's own (mrgi/perf/temporal.h).\n\n";

  o << "## Floor pass per scene\n\n| scene | size | samples | median ms | p95 ms | min ms |\n|---|---|---:|---:|---:|---:|\n";
  for (const SceneFloor& f : r.floors)
    o << "| " << f.scene << " | " << f.width << "x" << f.height << " | " << f.samples << " | " << fmt(f.median_ms, 3)
      << " | " << fmt(f.p95_ms, 3) << " | " << fmt(f.min_ms, 3) << " |\n";
  o << "\n";

  o << accuracy_by_set(r);
  const std::vector<LevelAggregate> levels = aggregate_levels(r);
  std::vector<size_t> plotted;
  const std::vector<size_t> front = front_of(levels, &plotted);
  std::vector<std::string> techniques;
  for (const BenchEntry& e : r.entries)
    if (std::find(techniques.begin(), techniques.end(), e.technique) == techniques.end()) techniques.push_back(e.technique);

  for (const std::string& t : techniques) {
    o << "## " << t << "\n\n";
    o << "| scene | level | sustained ms | p95 ms | ratio | CPU ms | split | memory MiB | RDE all | RDE real | RDE virtual | RMSE | SSIM | flicker |\n";
    o << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
    for (const BenchEntry& e : r.entries) {
      if (e.technique != t) continue;
      o << "| " << e.scene << " | " << e.level << " " << e.level_name << " | " << fmt(e.sustained_ms, 2) << " | "
        << fmt(e.frame.p95_ms, 2) << " | " << fmt(e.sustained_ratio, 1) << " | " << fmt(e.cpu_ms, 1) << " | "
        << (e.sustained_ms > 0.0 ? fmt(e.profiled.median_ms / e.sustained_ms, 2) : "-") << " | "
        << fmt(e.memory_mib, 1) << " | " << rde_cell(e.has_reference, e.error.all) << " | "
        << rde_cell(e.has_reference, e.error.real) << " | " << rde_cell(e.has_reference, e.error.virtual_) << " | "
        << (e.has_reference ? fmt(e.error.all.rmse8, 2) : "-") << " | "
        << (e.has_reference ? fmt(e.error.all.ssim, 4) : "-") << " | " << stability_cell(e) << " |\n";
    }
    for (size_t i = 0; i < levels.size(); ++i) {
      const LevelAggregate& l = levels[i];
      if (l.technique != t) continue;
      const bool on_front = std::find(front.begin(), front.end(), i) != front.end();
      o << "| **suite** (" << l.scenes << " scenes, mean) | " << l.level << " " << l.level_name
        << (on_front ? " (Pareto)" : "") << " | " << fmt(l.mean_median_ms, 2) << " | | " << fmt(l.mean_median_ratio, 1)
        << " | " << fmt(l.mean_cpu_ms, 1) << " | | " << fmt(l.max_memory_mib, 1) << " | " << rde_cell(l.has_reference, l.error.all) << " | "
        << rde_cell(l.has_reference, l.error.real) << " | " << rde_cell(l.has_reference, l.error.virtual_) << " | "
        << (l.has_reference ? fmt(l.error.all.rmse8, 2) : "-") << " | "
        << (l.has_reference ? fmt(l.error.all.ssim, 4) : "-") << " | |\n";
    }
    // Where the error is: the truth's regions (mrgi/metrics.h RdeReport::influenced, rest) and
    // how much light the output takes from or adds to the real pixels against the truth.
    o << "\nError by region (RDE over the virtual pixels, over the silhouette band (within " << kSilhouetteBandPx
      << " pixels of the reference mask's edge, either side), over the real pixels the virtual objects change in the "
         "truth, and over the real pixels they leave; *real change*: the signed sum of output - camera over the real pixels and "
         "channels, linear, against the same sum of truth - camera):\n\n"
         "| scene | level | RDE virtual | RDE silhouette | RDE influenced | RDE rest | real change | truth's | ratio |\n"
         "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const BenchEntry& e : r.entries) {
      if (e.technique != t || !e.has_reference) continue;
      const ErrorFigures& real = e.error.real;
      o << "| " << e.scene << " | " << e.level << " " << e.level_name << " | " << rde_cell(true, e.error.virtual_)
        << " | " << rde_cell(true, e.error.silhouette) << " | " << rde_cell(true, e.error.influenced) << " | " << rde_cell(true, e.error.rest) << " | "
        << fmt(real.change_sum, 1) << " | " << fmt(real.truth_change_sum, 1) << " | "
        << (std::abs(real.truth_change_sum) > 1e-9 ? fmt(real.change_sum / real.truth_change_sum, 2) : "-") << " |\n";
    }
    // What the objects do to the real scene, split by the truth's sign: each effect's mean change
    // per pixel and channel, the output's against the truth's.
    o << "\nError by effect (the real pixels the objects change in the truth, split by the sign of its change of "
         "luminance: *darkened* = their shadows and occlusion, *brightened* = their bounce light, colour bleeding, "
         "caustics and reflections; R, G, B: mean change per pixel, linear x 1000, output / truth):\n\n"
         "| scene | level | darkened px | RDE | R | G | B | brightened px | RDE | R | G | B |\n"
         "|---|---|---:|---:|---|---|---|---:|---:|---|---|---|\n";
    for (const BenchEntry& e : r.entries) {
      if (e.technique != t || !e.has_reference) continue;
      o << "| " << e.scene << " | " << e.level << " " << e.level_name;
      for (const ErrorFigures* f : {&e.error.darkened, &e.error.brightened}) {
        o << " | " << f->pixels << " | " << rde_cell(true, *f);
        for (int k = 0; k < 3; ++k) {
          const double n = f->pixels > 0 ? 1000.0 / double(f->pixels) : 0.0;
          o << " | " << (f->pixels > 0 ? fmt(f->change_rgb[k] * n, 1) + " / " + fmt(f->truth_change_rgb[k] * n, 1) : "-");
        }
      }
      o << " |\n";
    }
    o << "\n";
  }

  o << "## Where the frame goes\n\n![profiled passes per level, stacked, beside the sustained frame](passes.png)\n\n"
       "Every pass of every level, in ms: [passes.md](passes.md).\n\n";
  o << "## Frame time against error\n\n![frame ms against RDE, Pareto front](pareto.png)\n\n";
  o << "Pareto front (suite aggregate, no other level is both faster and more accurate):";
  if (front.empty()) o << " none (no level has a defined RDE)";
  o << "\n\n";
  for (size_t i : front)
    o << "- " << levels[i].technique << " level " << levels[i].level << " " << levels[i].level_name << ": "
      << fmt(levels[i].mean_median_ms, 2) << " ms, RDE " << fmt(levels[i].error.all.rde, 3) << "\n";
  bool any_sample = false;
  for (const SceneFloor& f : r.floors) {
    if (std::none_of(r.entries.begin(), r.entries.end(),
                     [&](const BenchEntry& e) { return e.scene == f.scene && e.sample_frame >= 0; }))
      continue;
    if (!any_sample)
      o << "\n## What the levels look like\n\nPer scene, its last measured frame with a reference: the camera, the "
           "reference and every technique level's output side by side, with the level's RDE and sustained ms.\n\n";
    any_sample = true;
    o << "- [" << f.scene << "](" << sample_sheet_path(f.scene) << ")\n";
  }
  if (check) {
    o << "\n## Regression check\n\n```\n" << check->summary() << "```\n";
  }
  return o.str();
}

namespace {
struct ScalingRow {
  std::string technique, level_name;
  int level = 0;
  std::vector<double> ms;  // per size: mean over scenes of the sustained ms (0 = not run)
};

std::vector<ScalingRow> scaling_rows(const std::vector<BenchResult>& by_size) {
  std::vector<ScalingRow> rows;
  for (size_t k = 0; k < by_size.size(); ++k)
    for (const LevelAggregate& a : aggregate_levels(by_size[k])) {
      auto it = std::find_if(rows.begin(), rows.end(), [&](const ScalingRow& r) {
        return r.technique == a.technique && r.level == a.level;
      });
      if (it == rows.end()) {
        rows.push_back({a.technique, a.level_name, a.level, std::vector<double>(by_size.size(), 0.0)});
        it = rows.end() - 1;
      }
      it->ms[k] = a.mean_median_ms;
    }
  return rows;
}

double size_pixels(const BenchResult& r) {
  return r.entries.empty() ? 0.0 : double(r.entries.front().width) * double(r.entries.front().height);
}
std::string size_name(const BenchResult& r) {
  return r.entries.empty() ? "-" : std::to_string(r.entries.front().width) + "x" + std::to_string(r.entries.front().height);
}
}  // namespace

std::string scaling_markdown(const std::vector<BenchResult>& by_size) {
  std::ostringstream o;
  o << "# mrgi bench: cost against output size\n\n";
  o << "Sustained ms per frame (mean over the scenes), per technique level and output size; *ms/MP* is that per "
       "megapixel of output; *growth* is the cost ratio between the largest and the smallest size divided by the "
       "pixel ratio (1.0 = cost grows in proportion to pixels, below 1 = per-pixel cost falls: fixed costs spread). "
       "Each size is its own run (floors and figures per size in its folder).\n\n";
  o << "| technique | level |";
  for (const BenchResult& r : by_size) o << " " << size_name(r) << " ms | ms/MP |";
  o << " growth |\n|---|---|";
  for (size_t k = 0; k < by_size.size(); ++k) o << "---:|---:|";
  o << "---:|\n";
  for (const ScalingRow& row : scaling_rows(by_size)) {
    o << "| " << row.technique << " | " << row.level << " " << row.level_name << " |";
    for (size_t k = 0; k < by_size.size(); ++k) {
      const double mp = size_pixels(by_size[k]) / 1e6;
      o << " " << (row.ms[k] > 0 ? fmt(row.ms[k], 2) : "-") << " | "
        << (row.ms[k] > 0 && mp > 0 ? fmt(row.ms[k] / mp, 1) : "-") << " |";
    }
    const size_t a = 0, b = by_size.size() - 1;
    const double pixel_ratio = size_pixels(by_size[b]) / std::max(1.0, size_pixels(by_size[a]));
    if (b > a && row.ms[a] > 0 && row.ms[b] > 0 && pixel_ratio > 0)
      o << " " << fmt(row.ms[b] / row.ms[a] / pixel_ratio, 2) << " |\n";
    else
      o << " - |\n";
  }
  return o.str();
}

nlohmann::json scaling_json(const std::vector<BenchResult>& by_size) {
  nlohmann::json j;
  nlohmann::json sizes = nlohmann::json::array();
  for (const BenchResult& r : by_size)
    sizes.push_back({{"size", size_name(r)}, {"pixels", size_pixels(r)}, {"floor_median_ms", r.floor_median_ms}});
  j["sizes"] = sizes;
  nlohmann::json rows = nlohmann::json::array();
  for (const ScalingRow& row : scaling_rows(by_size))
    rows.push_back({{"technique", row.technique}, {"level", row.level}, {"level_name", row.level_name},
                    {"mean_sustained_ms", row.ms}});
  j["levels"] = rows;
  return j;
}

// passes.md: every level's passes, median over scenes of each scene's median and p95 (ms), the
// ratio to the floor and the CPU ms; kept out of report.md, where one row a pass and level made
// the table most of the report.
std::string pass_table_markdown(const BenchResult& r) {
  std::ostringstream o;
  o << "# mrgi bench: time per pass\n\nProfiling mode (each pass submitted alone and host-timed): median over "
       "scenes of the per-scene median and p95, ms; ratio to the floor pass ("
    << fmt(r.floor_median_ms, 3) << " ms); CPU ms: the process's CPU time over the pass, every thread. The chart: "
       "[passes.png](passes.png); the rest of the run: [report.md](report.md).\n\n";
  const std::vector<LevelAggregate> levels = aggregate_levels(r);
  std::vector<std::string> techniques;
  for (const BenchEntry& e : r.entries)
    if (std::find(techniques.begin(), techniques.end(), e.technique) == techniques.end()) techniques.push_back(e.technique);
  for (const std::string& t : techniques) {
    o << "## " << t << "\n\n";
    o << "| level | pass | median ms | p95 ms | ratio | CPU ms |\n|---|---|---:|---:|---:|---:|\n";
    for (const LevelAggregate& l : levels) {
      if (l.technique != t) continue;
      std::vector<std::string> order;
      std::map<std::string, std::vector<double>> med, p95, ratio, cpu;
      for (const BenchEntry& e : r.entries) {
        if (e.technique != t || e.level != l.level) continue;
        for (const PassSummary& p : e.passes) {
          if (!med.count(p.name)) order.push_back(p.name);
          med[p.name].push_back(p.time.median_ms);
          p95[p.name].push_back(p.time.p95_ms);
          ratio[p.name].push_back(p.time.median_ratio);
          cpu[p.name].push_back(p.cpu_median_ms);
        }
      }
      for (const std::string& p : order)
        o << "| " << l.level << " " << l.level_name << " | " << p << " | " << fmt(percentile(med[p], 50), 3) << " | "
          << fmt(percentile(p95[p], 50), 3) << " | " << fmt(percentile(ratio[p], 50), 2) << " | "
          << fmt(percentile(cpu[p], 50), 2) << " |\n";
    }
    o << "\n";
  }
  return o.str();
}

Status write_bench_outputs(const std::string& dir_in, const BenchResult& r, const CheckReport* check) {
  // Only an earlier mrgi output (or an empty folder) is replaced, and a failed write removes
  // its own DIR.partial (mrgi/platform/output_dir.h).
  auto out = OutputDir::begin(dir_in, "--out");
  if (!out) return out.error();
  const std::string partial = out->partial();
  MRGI_TRY(write_text(partial + "/bench.json", bench_json(r, check).dump(2) + "\n"));
  MRGI_TRY(write_text(partial + "/bench.csv", bench_csv(r)));
  MRGI_TRY(write_text(partial + "/report.md", report_markdown(r, check)));
  MRGI_TRY(write_png(partial + "/pareto.png", render_pareto_plot(r)));
  MRGI_TRY(write_png(partial + "/passes.png", render_pass_plot(r)));
  MRGI_TRY(write_text(partial + "/passes.md", pass_table_markdown(r)));
  for (const SceneFloor& f : r.floors) {
    const std::optional<ImageRGB8> sheet = render_sample_sheet(r, f.scene);
    if (!sheet) continue;
    std::error_code ec;
    fs::create_directories(partial + "/images", ec);
    if (ec) return fail(ErrorKind::BadUsage, partial + "/images: cannot create the folder: " + ec.message());
    MRGI_TRY(write_png(partial + "/" + sample_sheet_path(f.scene), *sheet));
  }
  if (check) MRGI_TRY(write_text(partial + "/junit.xml", junit_xml(r, *check)));
  return out->commit();
}

}  // namespace mrgi::perf
