// passes.png: where each level's frame goes. One horizontal bar per technique level (the suite
// aggregate: per pass, the mean over the scenes of its median profiled ms), stacked by pass in
// the order the frame runs them, the nine costliest passes over the whole run in colours of
// their own and the rest as "other passes"; a black tick marks the level's sustained frame (mean
// over scenes), so the gap between bar and tick is what the profiled passes do not hold (host
// work, overlap). A dashed line marks the 33.3 ms budget.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/report.h"

namespace mrgi::perf {
// Names of their own: the unity build (MRGI_UNITY_LIBS) puts this file beside pareto_plot.cpp.
namespace {

constexpr int kBarsWidth = 1100;
constexpr float kBarsLeft = 210, kBarsRight = 290, kBarsTop = 70, kBarsBottom = 80, kBarHeight = 22, kBarGap = 10;
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
  const std::vector<LevelBar> bars = level_bars(result);
  const int height = int(kBarsTop + kBarsBottom + std::max<size_t>(1, bars.size()) * (kBarHeight + kBarGap) + kBarGap);
  Canvas cv(kBarsWidth, height, white);
  const float px0 = kBarsLeft, px1 = kBarsWidth - kBarsRight, py0 = kBarsTop, py1 = float(height) - kBarsBottom;

  // The costliest passes over the run get colours, in order of total time.
  std::map<std::string, double> total;
  double max_x = kBudgetMs;
  for (const LevelBar& b : bars) {
    double stack = 0.0;
    for (const auto& [name, ms] : b.passes) {
      total[name] += ms;
      stack += ms;
    }
    max_x = std::max({max_x, stack, b.sustained_ms});
  }
  std::vector<std::pair<double, std::string>> ranked;
  for (const auto& [name, ms] : total) ranked.emplace_back(-ms, name);
  std::sort(ranked.begin(), ranked.end());
  std::map<std::string, Rgb> colour;
  for (size_t i = 0; i < ranked.size() && i < kColouredPasses; ++i) colour[ranked[i].second] = kPalette[i];

  const PlotAxis ax = nice_axis(max_x);
  auto sx = [&](double x) { return float(px0 + (px1 - px0) * x / ax.max); };
  for (int i = 0; i * ax.step <= ax.max + 1e-9; ++i) {
    const float x = sx(i * ax.step);
    cv.line(x, py0, x, py1, 1.0f, grid);
    cv.line(x, py1, x, py1 + 6, 1.5f, black);
    const std::string t = tick_label(i * ax.step, ax.step);
    cv.text(x - Canvas::text_width(t, 2) / 2, py1 + 12, t, 2, black);
  }
  const float bx = sx(kBudgetMs);
  cv.line(bx, py0 - 6, bx, py1, 1.5f, {200, 0, 0}, 8.0f);
  cv.text(bx + 4, py0 - 16, "33.3 ms", 1.5f, {200, 0, 0});

  float y = py0 + kBarGap;
  for (const LevelBar& b : bars) {
    cv.text(px0 - 10 - Canvas::text_width(b.label, 1.5f), y + kBarHeight / 2 - Canvas::text_height(1.5f) / 2, b.label,
            1.5f, black);
    double x = 0.0;
    for (const auto& [name, ms] : b.passes) {
      auto it = colour.find(name);
      cv.fill_rect(sx(x), y, sx(x + ms), y + kBarHeight, it == colour.end() ? other : it->second);
      x += ms;
    }
    const float tx = sx(b.sustained_ms);
    cv.fill_rect(tx - 1.5f, y - 4, tx + 1.5f, y + kBarHeight + 4, black);
    y += kBarHeight + kBarGap;
  }
  if (bars.empty()) {
    const std::string msg = "no levels in this run";
    cv.text((px0 + px1) / 2 - Canvas::text_width(msg, 2) / 2, (py0 + py1) / 2, msg, 2, {200, 0, 0});
  }
  cv.line(px0, py1, px1, py1, 1.5f, black);
  cv.line(px0, py0, px0, py1, 1.5f, black);

  const std::string device = result.device.substr(0, result.device.find(" ("));
  char title[200];
  std::snprintf(title, sizeof title, "mrgi bench: time per pass, %s, LP_NUM_THREADS=%s", device.c_str(),
                result.lp_num_threads.empty() ? "unset" : result.lp_num_threads.c_str());
  cv.text(px0, 18, title, 2, black);
  cv.text(px0, 40, "bars: profiled passes (mean over scenes of each pass's median); tick: sustained frame", 1.5f, dark);
  const std::string xl = "ms per frame";
  cv.text((px0 + px1) / 2 - Canvas::text_width(xl, 2) / 2, py1 + 44, xl, 2, black);

  float ly = py0;
  const float lx = px1 + 20;
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
  return cv.image();
}

}  // namespace mrgi::perf
