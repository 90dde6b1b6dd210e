// passes.png: where each level's frame goes. One horizontal bar per technique level (the suite
// aggregate: per pass, the mean over the scenes of its median profiled ms), stacked by pass in
// the order the frame runs them, the nine costliest passes over the whole run in colours of
// their own and the rest as "other passes". Each bar has its own scale (its full width is the
// larger of its passes' sum and its sustained frame, written beside it in ms): levels of one
// run span 20 ms to seconds, and on a shared axis the fast levels were slivers. A black tick
// marks the level's sustained frame (mean over scenes), so the gap between the bar's end and the
// tick is what the profiled passes do not hold (host work, overlap); a red tick marks the
// 33.3 ms budget where it falls inside the bar's scale.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/report.h"

namespace mrgi::perf {
// Names of their own: the unity build (MRGI_UNITY_LIBS) puts this file beside pareto_plot.cpp.
namespace {

constexpr int kBarsWidth = 1480;
constexpr float kBarsLeft = 210, kBarsRight = 520, kBarsTop = 70, kBarsBottom = 80, kBarHeight = 22, kBarGap = 10;
constexpr size_t kColouredPasses = 9;
constexpr double kBudgetMs = 1000.0 / 30.0;

struct LevelBar {
  std::string label;
  std::vector<std::pair<std::string, double>> passes;  // in run order, ms
  double sustained_ms = 0.0;
};

std::vector<LevelBar> level_bars(const BenchResult& r) {
  std::vector<LevelBar> bars;
  std::vector<std::pair<std::string, int>> keys;
  for (const BenchEntry& e : r.entries)
    if (std::find(keys.begin(), keys.end(), std::make_pair(e.technique, e.level)) == keys.end())
      keys.emplace_back(e.technique, e.level);
  for (const auto& [technique, level] : keys) {
    LevelBar bar;
    std::map<std::string, double> sum;
    size_t scenes = 0;
    for (const BenchEntry& e : r.entries) {
      if (e.technique != technique || e.level != level) continue;
      bar.label = technique + " " + std::to_string(level) + " " + e.level_name;
      ++scenes;
      bar.sustained_ms += e.sustained_ms;
      for (const PassSummary& p : e.passes) {
        if (!sum.count(p.name)) bar.passes.emplace_back(p.name, 0.0);
        sum[p.name] += p.time.median_ms;
      }
    }
    for (auto& [name, ms] : bar.passes) ms = sum[name] / double(scenes);
    bar.sustained_ms /= double(std::max<size_t>(1, scenes));
    bars.push_back(std::move(bar));
  }
  return bars;
}

}  // namespace

ImageRGB8 render_pass_plot(const BenchResult& result) {
  const Rgb white{255, 255, 255}, black{0, 0, 0}, grid{225, 225, 225}, dark{70, 70, 70}, other{190, 190, 190};
  const Rgb budget_red{200, 0, 0};
  const std::vector<LevelBar> bars = level_bars(result);

  // The costliest passes over the run get colours, in order of total time.
  std::map<std::string, double> total;
  for (const LevelBar& b : bars)
    for (const auto& [name, ms] : b.passes) total[name] += ms;
  std::vector<std::pair<double, std::string>> ranked;
  for (const auto& [name, ms] : total) ranked.emplace_back(-ms, name);
  std::sort(ranked.begin(), ranked.end());
  std::map<std::string, Rgb> colour;
  for (size_t i = 0; i < ranked.size() && i < kColouredPasses; ++i) colour[ranked[i].second] = kPalette[i];

  // Tall enough for the bars and for the legend (pass names, "other passes", the two ticks).
  const size_t legend_rows = std::min(ranked.size(), kColouredPasses) + (ranked.size() > kColouredPasses) + 2;
  const float bars_h = float(std::max<size_t>(1, bars.size())) * (kBarHeight + kBarGap) + kBarGap;
  const float legend_h = 24.0f + 22.0f * float(legend_rows) + 10.0f;
  const int height = int(kBarsTop + kBarsBottom + std::max(bars_h, legend_h));
  Canvas cv(kBarsWidth, height, white);
  const float px0 = kBarsLeft, px1 = kBarsWidth - kBarsRight, py0 = kBarsTop, py1 = float(height) - kBarsBottom;

  // The x axis is the share of each level's own frame.
  for (int i = 0; i <= 4; ++i) {
    const float x = px0 + (px1 - px0) * float(i) / 4.0f;
    cv.line(x, py0, x, py1, 1.0f, grid);
    cv.line(x, py1, x, py1 + 6, 1.5f, black);
    const std::string t = std::to_string(i * 25) + " %";
    cv.text(x - Canvas::text_width(t, 2) / 2, py1 + 12, t, 2, black);
  }

  float y = py0 + kBarGap;
  for (const LevelBar& b : bars) {
    cv.text(px0 - 10 - Canvas::text_width(b.label, 1.5f), y + kBarHeight / 2 - Canvas::text_height(1.5f) / 2, b.label,
            1.5f, black);
    double stack = 0.0;
    for (const auto& [name, ms] : b.passes) stack += ms;
    const double scale = std::max({stack, b.sustained_ms, 1e-9});
    auto sx = [&](double ms) { return float(px0 + (px1 - px0) * ms / scale); };
    double x = 0.0;
    for (const auto& [name, ms] : b.passes) {
      auto it = colour.find(name);
      cv.fill_rect(sx(x), y, sx(x + ms), y + kBarHeight, it == colour.end() ? other : it->second);
      x += ms;
    }
    const float tx = sx(b.sustained_ms);
    cv.fill_rect(tx - 1.5f, y - 4, tx + 1.5f, y + kBarHeight + 4, black);
    if (kBudgetMs < scale) {
      const float bx = sx(kBudgetMs);
      cv.fill_rect(bx - 1.0f, y - 4, bx + 1.0f, y + kBarHeight + 4, budget_red);
    }
    char ms_text[64];
    std::snprintf(ms_text, sizeof ms_text, "%.1f ms (passes %.1f)", b.sustained_ms, stack);
    cv.text(px1 + 8, y + kBarHeight / 2 - Canvas::text_height(1.5f) / 2, ms_text, 1.5f, dark);
    y += kBarHeight + kBarGap;
  }
  if (bars.empty()) {
    const std::string msg = "no levels in this run";
    cv.text((px0 + px1) / 2 - Canvas::text_width(msg, 2) / 2, (py0 + py1) / 2, msg, 2, budget_red);
  }
  cv.line(px0, py1, px1, py1, 1.5f, black);
  cv.line(px0, py0, px0, py1, 1.5f, black);

  const std::string device = result.device.substr(0, result.device.find(" ("));
  char title[200];
  std::snprintf(title, sizeof title, "mrgi bench: time per pass, %s, LP_NUM_THREADS=%s", device.c_str(),
                result.lp_num_threads.empty() ? "unset" : result.lp_num_threads.c_str());
  cv.text(px0, 18, title, 2, black);
  cv.text(px0, 40,
          "each bar on its own scale: profiled passes (mean over scenes of each pass's median); ms: sustained frame",
          1.5f, dark);
  const std::string xl = "share of the level's frame (its sustained ms or its passes' sum, the larger)";
  cv.text((px0 + px1) / 2 - Canvas::text_width(xl, 2) / 2, py1 + 44, xl, 2, black);

  float ly = py0;
  const float lx = px1 + 230;
  cv.text(lx, ly, "pass", 2, black);
  ly += 24;
  for (size_t i = 0; i < ranked.size() && i < kColouredPasses; ++i) {
    cv.fill_rect(lx, ly, lx + 16, ly + 14, kPalette[i]);
    cv.text(lx + 24, ly, ranked[i].second, 1.5f, black);
    ly += 22;
  }
  if (ranked.size() > kColouredPasses) {
    cv.fill_rect(lx, ly, lx + 16, ly + 14, other);
    cv.text(lx + 24, ly, "other passes", 1.5f, black);
    ly += 22;
  }
  cv.fill_rect(lx + 6.5f, ly - 2, lx + 9.5f, ly + 16, black);
  cv.text(lx + 24, ly, "sustained frame", 1.5f, black);
  ly += 22;
  cv.fill_rect(lx + 7.0f, ly - 2, lx + 9.0f, ly + 16, budget_red);
  cv.text(lx + 24, ly, "33.3 ms budget", 1.5f, black);
  return cv.image();
}

}  // namespace mrgi::perf
