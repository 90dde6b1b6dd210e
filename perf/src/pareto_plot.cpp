// pareto.png: suite-aggregate median frame ms (x) against pooled RDE (y), one colour and marker
// per technique, the Pareto front as a dashed line through its points, a legend at the right.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/pareto.h"
#include "mrgi/perf/report.h"

namespace mrgi::perf {
namespace {

constexpr int kWidth = 960, kHeight = 640;
constexpr float kLeft = 90, kRight = 230, kTop = 60, kBottom = 80;  // plot-area margins, px

const Marker kMarkers[] = {Marker::Circle, Marker::Square, Marker::TriangleUp, Marker::Diamond,
                           Marker::Plus,   Marker::Cross,  Marker::TriangleDown};

}  // namespace

ImageRGB8 render_pareto_plot(const BenchResult& result) {
  const Rgb white{255, 255, 255}, black{0, 0, 0}, grid{225, 225, 225}, dark{70, 70, 70};
  Canvas cv(kWidth, kHeight, white);
  const float px0 = kLeft, px1 = kWidth - kRight, py0 = kTop, py1 = kHeight - kBottom;

  const std::vector<LevelAggregate> levels = aggregate_levels(result);
  std::vector<ParetoPoint> points;
  std::vector<size_t> plotted;  // indices into levels with a defined RDE
  for (size_t i = 0; i < levels.size(); ++i)
    if (levels[i].has_reference && levels[i].error.all.rde_defined) {
      points.push_back({levels[i].mean_median_ms, levels[i].error.all.rde});
      plotted.push_back(i);
    }
  double max_x = 0.0, max_y = 0.0;
  for (const ParetoPoint& p : points) {
    max_x = std::max(max_x, p.cost);
    max_y = std::max(max_y, p.error);
  }
  double min_x = max_x;
  for (const ParetoPoint& p : points) min_x = std::min(min_x, p.cost);
  const PlotAxis ax = nice_axis(max_x), ay = nice_axis(max_y);
  // Frame times of the levels of different techniques span decades (a 100 ms level beside a 10 s
  // one): a linear axis would crowd every cheap level into one corner, so the x axis turns
  // logarithmic when the largest time is over 20 times the smallest.
  const bool log_x = min_x > 0.0 && max_x / min_x > 20.0;
  const double lx0 = log_x ? std::floor(std::log10(min_x / 1.2)) : 0.0;
  const double lx1 = log_x ? std::ceil(std::log10(max_x * 1.2)) : 1.0;
  auto sx = [&](double x) {
    if (log_x) return float(px0 + (px1 - px0) * (std::log10(std::max(x, 1e-300)) - lx0) / (lx1 - lx0));
    return float(px0 + (px1 - px0) * x / ax.max);
  };
  auto sy = [&](double y) { return float(py1 - (py1 - py0) * y / ay.max); };

  // Grid, ticks and tick labels.
  auto x_tick = [&](double v, const std::string& t, bool major) {
    const float x = sx(v);
    cv.line(x, py0, x, py1, major ? 1.0f : 0.5f, grid);
    cv.line(x, py1, x, py1 + (major ? 6 : 3), 1.5f, black);
    if (!t.empty()) cv.text(x - Canvas::text_width(t, 2) / 2, py1 + 12, t, 2, black);
  };
  if (log_x) {
    for (int e = int(lx0); e <= int(lx1); ++e)
      for (int m : {1, 2, 5}) {
        const double v = m * std::pow(10.0, e);
        if (std::log10(v) > lx1 + 1e-9) break;
        x_tick(v, m == 1 || (lx1 - lx0) <= 2.0 ? tick_label(v, std::min(1.0, v)) : "", m == 1);
      }
  } else {
    for (int i = 0; i * ax.step <= ax.max + 1e-9; ++i)
      x_tick(i * ax.step, tick_label(i * ax.step, ax.step), true);
  }
  for (int i = 0; i * ay.step <= ay.max + 1e-9; ++i) {
    const double v = i * ay.step;
    const float y = sy(v);
    cv.line(px0, y, px1, y, 1.0f, grid);
    cv.line(px0 - 6, y, px0, y, 1.5f, black);
    const std::string t = tick_label(v, ay.step);
    cv.text(px0 - 12 - Canvas::text_width(t, 2), y - Canvas::text_height(2) / 2, t, 2, black);
  }
  cv.line(px0, py1, px1, py1, 1.5f, black);
  cv.line(px0, py0, px0, py1, 1.5f, black);

  // Titles and axis labels.
  // The device's short name: lavapipe reports "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string device = result.device.substr(0, result.device.find(" ("));
  char title[160];
  std::snprintf(title, sizeof title, "mrgi bench: frame time vs error, %s, LP_NUM_THREADS=%s", device.c_str(),
                result.lp_num_threads.empty() ? "unset" : result.lp_num_threads.c_str());
  cv.text(px0, 18, title, 2, black);
  char sub[160];
  std::snprintf(sub, sizeof sub, "suite aggregate per technique level, floor pass %.3f ms, %d frames + %d warm-up per run",
                result.floor_median_ms, result.frames, result.warmup);
  cv.text(px0, 40, sub, 1.5f, dark);
  const std::string xl = std::string("sustained ms per frame (mean over scenes") + (log_x ? ", log scale)" : ")");
  cv.text((px0 + px1) / 2 - Canvas::text_width(xl, 2) / 2, py1 + 44, xl, 2, black);
  const std::string yl = "RDE, all pixels (pooled over scenes and frames)";
  cv.text(22, (py0 + py1) / 2 + Canvas::text_width(yl, 2) / 2, yl, 2, black, true);

  // One style per technique, in order of appearance.
  std::map<std::string, size_t> style;
  std::vector<std::string> techniques;
  for (const LevelAggregate& l : levels)
    if (style.emplace(l.technique, style.size()).second) techniques.push_back(l.technique);

  const std::vector<size_t> front = pareto_front(points);
  for (size_t k = 1; k < front.size(); ++k)
    cv.line(sx(points[front[k - 1]].cost), sy(points[front[k - 1]].error), sx(points[front[k]].cost),
            sy(points[front[k]].error), 2.0f, dark, 8.0f);
  for (size_t k : front) cv.marker(sx(points[k].cost), sy(points[k].error), Marker::Circle, 10.0f, white, dark);

  // Labels go to the first of four places around their point that overlaps no earlier label.
  struct Box {
    float x0, y0, x1, y1;
  };
  std::vector<Box> placed;
  for (size_t k = 0; k < points.size(); ++k) {
    const LevelAggregate& l = levels[plotted[k]];
    const size_t st = style[l.technique];
    const Rgb c = kPalette[st % std::size(kPalette)];
    const float x = sx(points[k].cost), y = sy(points[k].error);
    cv.marker(x, y, kMarkers[st % std::size(kMarkers)], 6.0f, c, black);
    const float tw = Canvas::text_width(l.level_name, 1.5f), th = Canvas::text_height(1.5f);
    const Box candidates[] = {{x + 9, y - 9 - th, x + 9 + tw, y - 9},
                              {x + 9, y + 9, x + 9 + tw, y + 9 + th},
                              {x - 9 - tw, y - 9 - th, x - 9, y - 9},
                              {x - 9 - tw, y + 9, x - 9, y + 9 + th}};
    Box chosen = candidates[0];
    for (const Box& b : candidates) {
      bool free = true;
      for (const Box& p : placed) free = free && (b.x1 < p.x0 || b.x0 > p.x1 || b.y1 < p.y0 || b.y0 > p.y1);
      if (free) {
        chosen = b;
        break;
      }
    }
    placed.push_back(chosen);
    cv.text(chosen.x0, chosen.y0, l.level_name, 1.5f, dark);
  }
  if (points.empty()) {
    const std::string msg = "no RDE to plot: the scenes have no reference frames";
    cv.text((px0 + px1) / 2 - Canvas::text_width(msg, 2) / 2, (py0 + py1) / 2, msg, 2, {200, 0, 0});
  }

  // Legend.
  float ly = py0 + 10;
  const float lx = px1 + 20;
  cv.text(lx, ly, "technique", 2, black);
  ly += 26;
  for (const std::string& t : techniques) {
    const size_t st = style[t];
    cv.marker(lx + 8, ly + 7, kMarkers[st % std::size(kMarkers)], 6.0f, kPalette[st % std::size(kPalette)], black);
    cv.text(lx + 24, ly, t, 2, black);
    ly += 24;
  }
  ly += 6;
  cv.line(lx, ly + 7, lx + 18, ly + 7, 2.0f, dark, 5.0f);
  cv.marker(lx + 8, ly + 7, Marker::Circle, 6.0f, white, dark);
  cv.text(lx + 24, ly, "Pareto front", 2, black);
  ly += 30;
  cv.text(lx, ly, "lower left is better", 1.5f, dark);
  return cv.image();
}

}  // namespace mrgi::perf
