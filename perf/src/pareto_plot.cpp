// pareto.png: suite-aggregate sustained frame ms (x) against pooled RDE (y) over all, real and
// virtual pixels in three panels, one colour and marker per technique, each panel's Pareto front
// as a dashed line through its points, labels placed where they overlap nothing, a legend at the
// right.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/pareto.h"
#include "mrgi/perf/report.h"

namespace mrgi::perf {
namespace {

// Three panels (all, real, virtual pixels) of kPanelWidth px each, then the legend.
constexpr int kWidth = 1640, kHeight = 600;
constexpr float kPanelWidth = 480, kLeft = 70, kGap = 20, kTop = 90, kBottom = 70;  // px

const Marker kMarkers[] = {Marker::Circle, Marker::Square, Marker::TriangleUp, Marker::Diamond,
                           Marker::Plus,   Marker::Cross,  Marker::TriangleDown};

}  // namespace

ImageRGB8 render_pareto_plot(const BenchResult& result) {
  const Rgb white{255, 255, 255}, black{0, 0, 0}, grid{225, 225, 225}, dark{70, 70, 70};
  Canvas cv(kWidth, kHeight, white);
  const std::vector<LevelAggregate> levels = aggregate_levels(result);

  // One style per technique, in order of appearance.
  std::map<std::string, size_t> style;
  std::vector<std::string> techniques;
  for (const LevelAggregate& l : levels)
    if (style.emplace(l.technique, style.size()).second) techniques.push_back(l.technique);

  // The three pixel sets side by side, each its own y axis, one x axis (frame time) for all.
  auto figures = [](const LevelAggregate& l, int set) -> const ErrorFigures& {
    return set == 0 ? l.error.all : set == 1 ? l.error.real : l.error.virtual_;
  };
  const char* set_names[] = {"all pixels", "real pixels", "virtual pixels"};
  double min_x = 0.0, max_x = 0.0;
  bool any = false;
  for (const LevelAggregate& l : levels)
    if (l.has_reference && l.error.all.rde_defined) {
      min_x = any ? std::min(min_x, l.mean_median_ms) : l.mean_median_ms;
      max_x = std::max(max_x, l.mean_median_ms);
      any = true;
    }
  // Frame times of the levels of different techniques span decades (a 100 ms level beside a 10 s
  // one): a linear axis would crowd every cheap level into one corner, so the x axis turns
  // logarithmic when the largest time is over 20 times the smallest.
  const bool log_x = any && min_x > 0.0 && max_x / min_x > 20.0;
  const PlotAxis ax = nice_axis(max_x);
  const double lx0 = log_x ? std::floor(std::log10(min_x / 1.2)) : 0.0;
  const double lx1 = log_x ? std::ceil(std::log10(max_x * 1.2)) : 1.0;

  for (int set = 0; set < 3; ++set) {
    const float px0 = kLeft + float(set) * kPanelWidth, px1 = px0 + kPanelWidth - kLeft - kGap;
    const float py0 = kTop, py1 = kHeight - kBottom;
    std::vector<ParetoPoint> points;
    std::vector<size_t> plotted;  // indices into levels with a defined RDE
    for (size_t i = 0; i < levels.size(); ++i)
      if (levels[i].has_reference && figures(levels[i], set).rde_defined) {
        points.push_back({levels[i].mean_median_ms, figures(levels[i], set).rde});
        plotted.push_back(i);
      }
    double max_y = 0.0;
    for (const ParetoPoint& p : points) max_y = std::max(max_y, p.error);
    const PlotAxis ay = nice_axis(max_y);
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
      if (!t.empty()) cv.text(x - Canvas::text_width(t, 1.5f) / 2, py1 + 12, t, 1.5f, black);
    };
    if (log_x) {
      for (int e = int(lx0); e <= int(lx1); ++e)
        for (int m : {1, 2, 5}) {
          const double v = m * std::pow(10.0, e);
          if (std::log10(v) > lx1 + 1e-9) break;
          x_tick(v, m == 1 || (lx1 - lx0) <= 2.0 ? tick_label(v, std::min(1.0, v)) : "", m == 1);
        }
    } else {
      for (int i = 0; i * ax.step <= ax.max + 1e-9; ++i) x_tick(i * ax.step, tick_label(i * ax.step, ax.step), true);
    }
    for (int i = 0; i * ay.step <= ay.max + 1e-9; ++i) {
      const double v = i * ay.step;
      const float y = sy(v);
      cv.line(px0, y, px1, y, 1.0f, grid);
      cv.line(px0 - 6, y, px0, y, 1.5f, black);
      const std::string t = tick_label(v, ay.step);
      cv.text(px0 - 10 - Canvas::text_width(t, 1.5f), y - Canvas::text_height(1.5f) / 2, t, 1.5f, black);
    }
    cv.line(px0, py1, px1, py1, 1.5f, black);
    cv.line(px0, py0, px0, py1, 1.5f, black);
    const std::string heading = std::string("RDE, ") + set_names[set];
    cv.text(px0, py0 - 22, heading, 2, black);

    const std::vector<size_t> front = pareto_front(points);
    for (size_t k = 1; k < front.size(); ++k)
      cv.line(sx(points[front[k - 1]].cost), sy(points[front[k - 1]].error), sx(points[front[k]].cost),
              sy(points[front[k]].error), 2.0f, dark, 8.0f);
    for (size_t k : front) cv.marker(sx(points[k].cost), sy(points[k].error), Marker::Circle, 10.0f, white, dark);

    // Markers first, then labels, each label at the first of eight places around its point that
    // overlaps no marker and no earlier label, or left out (the legend and the report name every
    // level) where none is free.
    struct Box {
      float x0, y0, x1, y1;
    };
    std::vector<Box> taken;
    for (size_t k = 0; k < points.size(); ++k) {
      const size_t st = style[levels[plotted[k]].technique];
      const float x = sx(points[k].cost), y = sy(points[k].error);
      cv.marker(x, y, kMarkers[st % std::size(kMarkers)], 6.0f, kPalette[st % std::size(kPalette)], black);
      taken.push_back({x - 7, y - 7, x + 7, y + 7});
    }
    for (size_t k = 0; k < points.size(); ++k) {
      const LevelAggregate& l = levels[plotted[k]];
      const float x = sx(points[k].cost), y = sy(points[k].error);
      const float tw = Canvas::text_width(l.level_name, 1.5f), th = Canvas::text_height(1.5f);
      const Box candidates[] = {{x + 9, y - 9 - th, x + 9 + tw, y - 9},   {x + 9, y + 9, x + 9 + tw, y + 9 + th},
                                {x - 9 - tw, y - 9 - th, x - 9, y - 9},   {x - 9 - tw, y + 9, x - 9, y + 9 + th},
                                {x + 10, y - th / 2, x + 10 + tw, y + th / 2}, {x - 10 - tw, y - th / 2, x - 10, y + th / 2},
                                {x - tw / 2, y - 12 - th, x + tw / 2, y - 12}, {x - tw / 2, y + 12, x + tw / 2, y + 12 + th}};
      for (const Box& b : candidates) {
        bool free = b.x0 >= px0 && b.x1 <= px1 + kGap - 4 && b.y0 >= py0 - 4 && b.y1 <= py1;
        for (const Box& p : taken) free = free && (b.x1 < p.x0 || b.x0 > p.x1 || b.y1 < p.y0 || b.y0 > p.y1);
        if (!free) continue;
        taken.push_back(b);
        cv.text(b.x0, b.y0, l.level_name, 1.5f, dark);
        break;
      }
    }
    if (points.empty()) {
      const std::string msg = "no RDE to plot";
      cv.text((px0 + px1) / 2 - Canvas::text_width(msg, 2) / 2, (py0 + py1) / 2, msg, 2, {200, 0, 0});
    }
    const std::string xl = std::string("sustained ms (scene mean") + (log_x ? ", log)" : ")");
    cv.text((px0 + px1) / 2 - Canvas::text_width(xl, 1.5f) / 2, py1 + 40, xl, 1.5f, black);
  }

  // Titles.
  // The device's short name: lavapipe reports "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string device = result.device.substr(0, result.device.find(" ("));
  char title[160];
  std::snprintf(title, sizeof title, "mrgi bench: frame time vs error, %s, LP_NUM_THREADS=%s", device.c_str(),
                result.lp_num_threads.empty() ? "unset" : result.lp_num_threads.c_str());
  cv.text(kLeft, 14, title, 2, black);
  char sub[200];
  std::snprintf(sub, sizeof sub,
                "suite aggregate per technique level (RDE pooled over scenes and frames), floor pass %.3f ms, %d frames "
                "+ %d warm-up per run",
                result.floor_median_ms, result.frames, result.warmup);
  cv.text(kLeft, 36, sub, 1.5f, dark);

  // Legend.
  float ly = kTop + 10;
  const float lx = kLeft + 3 * kPanelWidth - kLeft + 10;
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
