// The A/B comparison's outputs: compare.md, compare.json, junit.xml, ratios.png.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mrgi/perf/ab_compare.h"
#include "mrgi/perf/canvas.h"
#include "mrgi/perf/regression.h"
#include "mrgi/perf/stats.h"
#include "mrgi/image.h"

namespace mrgi::perf {
namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::vector<double> finite(const std::vector<double>& v) {
  std::vector<double> o;
  for (double x : v)
    if (std::isfinite(x) && x > 0.0) o.push_back(x);
  return o;
}

std::string rule_text(const AbResult& r) {
  return "each quantity: the median of the paired ratios candidate / base with a bootstrap 95 % interval; "
         "one-sided Wilcoxon signed-rank test (exact) that the log ratios exceed ln(1 + " +
         fmt("%.3g", r.rule.min_slowdown) + "); Holm's adjustment over all " + std::to_string(r.quantities.size()) +
         " quantities; an alarm where the adjusted p-value is at most " + fmt("%.3g", r.rule.alpha) +
         " (family-wise false-alarm rate " + fmt("%.3g", r.rule.alpha) + ")";
}

std::string markdown(const AbResult& r) {
  std::ostringstream md;
  md << "# A/B comparison: candidate against base\n\n";
  md << "- base: `" << r.base_binary << "`" << (r.base_commit.empty() ? "" : " (commit " + r.base_commit + ")") << "\n";
  md << "- candidate: `" << r.candidate_binary << "`"
     << (r.candidate_commit.empty() ? "" : " (commit " + r.candidate_commit + ")") << "\n";
  md << "- device: " << r.device << ", LP_NUM_THREADS=" << (r.lp_num_threads.empty() ? "unset" : r.lp_num_threads)
     << "; " << r.pairs << " pairs per entry, each measurement " << r.warmup << " warm-up + " << r.frames
     << " sustained frames (2 in flight) and " << r.profile_frames << " profiling-mode frames; " << fmt("%.0f", r.duration_s)
     << " s\n";
  md << "- rule: " << rule_text(r) << "\n";
  const size_t needed = min_pairs_for(r.quantities.size(), r.rule.alpha);
  if (size_t(r.pairs) < needed)
    md << "- **with " << r.pairs << " pairs no quantity of a family of " << r.quantities.size()
       << " can alarm (it needs " << needed << "): raise --pairs**\n";
  md << "\n**" << (r.alarms() ? std::to_string(r.alarms()) + " alarm" + (r.alarms() > 1 ? "s" : "") : "No alarm")
     << "** over " << r.quantities.size() << " quantities.\n\n";
  md << "Base and candidate: medians over the pairs; ms for sustained_ms and cpu_ms, and for a pass its fastest "
        "profiled frame over the rest of the measurement's passes (the machine's drift between measurements "
        "moves both alike); for the scheduler (level auto) " << kSchedulerMetric << ", (n + 2) / (k + 1) for k of "
        "n frames within the budget (1.05: 95 %), larger worse as a time is.\n\n";
  md << "| entry | quantity | base (median) | candidate (median) | ratio (median) | 95 % interval | p | Holm p | alarm |\n";
  md << "|---|---|---:|---:|---:|---|---:|---:|---|\n";
  for (const AbQuantity& q : r.quantities) {
    const AbJudgement& j = q.judgement;
    md << "| " << q.entry() << " | " << q.metric << " | "
       << fmt(q.metric.rfind("pass:", 0) == 0 ? "%.4f" : "%.2f", median(finite(q.base))) << " | "
       << fmt(q.metric.rfind("pass:", 0) == 0 ? "%.4f" : "%.2f", median(finite(q.candidate))) << " | "
       << fmt("%.3f", j.median_ratio) << " | " << fmt("%.3f", j.ratio_low) << "-" << fmt("%.3f", j.ratio_high) << " | "
       << fmt("%.2g", j.p_value) << " | " << fmt("%.2g", j.p_adjusted) << " | " << (j.alarm ? "**slower**" : "") << " |\n";
  }
  md << "\n![median ratio per quantity](ratios.png)\n";
  return md.str();
}

nlohmann::json to_json(const AbResult& r) {
  nlohmann::json j = {{"base", {{"binary", r.base_binary}, {"commit", r.base_commit}}},
                      {"candidate", {{"binary", r.candidate_binary}, {"commit", r.candidate_commit}}},
                      {"device", r.device},
                      {"lp_num_threads", r.lp_num_threads},
                      {"pairs", r.pairs},
                      {"frames", r.frames},
                      {"warmup", r.warmup},
                      {"profile_frames", r.profile_frames},
                      {"rule", {{"min_slowdown", r.rule.min_slowdown}, {"alpha", r.rule.alpha}, {"text", rule_text(r)}}},
                      {"duration_s", r.duration_s},
                      {"alarms", r.alarms()}};
  nlohmann::json qs = nlohmann::json::array();
  for (const AbQuantity& q : r.quantities) {
    const AbJudgement& a = q.judgement;
    auto samples = [](const std::vector<double>& v) {
      nlohmann::json o = nlohmann::json::array();
      for (double x : v) o.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
      return o;
    };
    qs.push_back({{"scene", q.scene}, {"technique", q.technique}, {"level", q.level_name}, {"metric", q.metric},
                  {"unit", q.metric.rfind("pass:", 0) == 0 ? "the pass's fastest profiled frame over the rest of the measurement's passes"
                           : q.metric == kSchedulerMetric ? "(n + 2) / (k + 1) for k of n frames within the budget"
                                                          : "ms"},
                  {"base", samples(q.base)}, {"candidate", samples(q.candidate)}, {"pairs", a.pairs},
                  {"median_ratio", a.median_ratio}, {"ratio_low", a.ratio_low}, {"ratio_high", a.ratio_high},
                  {"p", a.p_value}, {"p_holm", a.p_adjusted}, {"alarm", a.alarm}});
  }
  j["quantities"] = qs;
  return j;
}

std::string junit(const AbResult& r) {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<testsuite name=\"mrgi-perf-compare\" tests=\"" << r.quantities.size() << "\" failures=\"" << r.alarms()
    << "\" time=\"" << fmt("%.1f", r.duration_s) << "\">\n";
  for (const AbQuantity& q : r.quantities) {
    const AbJudgement& j = q.judgement;
    x << "  <testcase classname=\"" << xml_escape(q.scene + "." + q.technique + "." + q.level_name) << "\" name=\""
      << xml_escape(q.metric) << "\">";
    if (j.alarm)
      x << "\n    <failure message=\"" << xml_escape("slower: median ratio " + fmt("%.3f", j.median_ratio) + " (" +
                                                      fmt("%.3f", j.ratio_low) + "-" + fmt("%.3f", j.ratio_high) +
                                                      "), Holm p " + fmt("%.2g", j.p_adjusted))
        << "\"/>\n  ";
    x << "</testcase>\n";
  }
  x << "</testsuite>\n";
  return x.str();
}

// Each quantity a row: its median ratio (a dot) and 95 % interval (a bar) on a common axis
// around 1, alarms in red, the margin (1 + min_slowdown) dashed.
ImageRGB8 ratio_plot(const AbResult& r) {
  const int row = 14, left = 330, right = 40, top = 40, bottom = 40;
  const int w = 900, h = top + bottom + row * int(std::max<size_t>(r.quantities.size(), 1));
  Canvas c(w, h, {255, 255, 255});
  double lo = 0.9, hi = 1.1;
  for (const AbQuantity& q : r.quantities) {
    lo = std::min(lo, q.judgement.ratio_low);
    hi = std::max(hi, q.judgement.ratio_high);
  }
  lo = std::max(lo, 0.5);
  hi = std::min(hi, 2.0);
  auto x_of = [&](double v) { return float(left + (w - left - right) * (std::clamp(v, lo, hi) - lo) / (hi - lo)); };
  const Rgb grey{150, 150, 150}, black{0, 0, 0}, red{214, 39, 40}, blue{31, 119, 180};
  c.text(10, 10, "median ratio candidate / base, 95 % interval (red: alarm)", 1.5f, black);
  c.line(x_of(1.0), float(top - 5), x_of(1.0), float(h - bottom), 1.0f, grey);
  c.line(x_of(1.0 + r.rule.min_slowdown), float(top - 5), x_of(1.0 + r.rule.min_slowdown), float(h - bottom), 1.0f,
         grey, 4.0f);
  double step = 0.5;
  for (double c : {0.01, 0.02, 0.05, 0.1, 0.2, 0.5})
    if ((hi - lo) / c <= 10.0) {
      step = c;
      break;
    }
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9; t += step) {
    c.line(x_of(t), float(h - bottom), x_of(t), float(h - bottom + 4), 1.0f, black);
    c.text(x_of(t) - 10, float(h - bottom + 8), fmt("%.2f", t), 1.0f, black);
  }
  for (size_t i = 0; i < r.quantities.size(); ++i) {
    const AbQuantity& q = r.quantities[i];
    const float y = float(top + row * int(i) + row / 2);
    const Rgb col = q.judgement.alarm ? red : blue;
    c.text(10, y - 4, q.entry() + " " + q.metric, 1.0f, black);
    c.line(x_of(q.judgement.ratio_low), y, x_of(q.judgement.ratio_high), y, 2.0f, col);
    c.marker(x_of(q.judgement.median_ratio), y, Marker::Circle, 3.5f, col, black);
  }
  return c.image();
}

}  // namespace

Status write_ab_outputs(const std::string& dir, const AbResult& r) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(ErrorKind::BadInput, dir + ": cannot be created (" + ec.message() + ")");
  std::ofstream(dir + "/compare.md") << markdown(r);
  std::ofstream(dir + "/compare.json") << to_json(r).dump(2) << "\n";
  std::ofstream(dir + "/junit.xml") << junit(r);
  return write_png(dir + "/ratios.png", ratio_plot(r));
}

}  // namespace mrgi::perf
