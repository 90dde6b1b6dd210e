// trace.png of the load test: three strips over the frames, the load phases shaded behind them:
// the level (scheduled: a blue step line; oracle: grey), the internal-resolution factor, and
// each frame's cost against the budget (a red dashed line).
#include <algorithm>
#include <cstdio>

#include "mrgi/perf/canvas.h"
#include "mrgi/perf/load_test.h"

namespace mrgi::perf {

ImageRGB8 render_load_trace(const LoadTestResult& r) {
  constexpr int kW = 1100, kH = 720;
  constexpr float kLeft = 90, kRight = 30, kTop = 60;
  const Rgb white{255, 255, 255}, black{0, 0, 0}, grey{150, 150, 150}, blue{31, 119, 180}, red{200, 0, 0};
  const Rgb shade[] = {{255, 236, 210}, {220, 235, 255}, {225, 245, 225}};
  Canvas cv(kW, kH, white);
  const int n = int(r.scheduled.size());
  const float x0 = kLeft, x1 = kW - kRight;
  auto sx = [&](double k) { return float(x0 + (x1 - x0) * k / std::max(1, n)); };
  struct Strip {
    float y0, y1;
  };
  const Strip strips[3] = {{kTop, kTop + 180}, {kTop + 215, kTop + 335}, {kTop + 370, kTop + 600}};
  // Phases behind every strip, with their names above the first.
  std::vector<std::string> kinds;
  for (const LoadPhase& p : r.phases) {
    auto it = std::find(kinds.begin(), kinds.end(), p.what);
    const size_t c = size_t(it - kinds.begin());
    if (it == kinds.end()) kinds.push_back(p.what);
    for (const Strip& s : strips) cv.fill_rect(sx(p.from), s.y0, sx(p.to), s.y1, shade[c % 3], 0.8f);
  }
  float lx = x0;
  for (size_t c = 0; c < kinds.size(); ++c) {
    cv.fill_rect(lx, 40, lx + 14, 52, shade[c % 3]);
    cv.text(lx + 18, 40, kinds[c], 1.5f, black);
    lx += 30 + Canvas::text_width(kinds[c], 1.5f);
  }
  char title[256];
  std::snprintf(title, sizeof title, "mrgi load test: %s on %s, budget %.1f ms: %.1f %% within, %.2f switches/s",
                r.settings.technique.c_str(), r.settings.scene.c_str(), r.settings.budget_ms, 100.0 * r.share_within,
                r.switches_per_s);
  cv.text(x0, 12, title, 2, black);

  // Strip 1: level (0 at the top: best).
  const int levels = std::max<int>(1, int(r.level_names.size()));
  auto ly = [&](double lv) { return strips[0].y0 + 10 + (strips[0].y1 - strips[0].y0 - 20) * float(lv) / float(std::max(1, levels - 1)); };
  for (int lv = 0; lv < levels; ++lv) {
    cv.line(x0, ly(lv), x1, ly(lv), 0.5f, {220, 220, 220});
    cv.text(10, ly(lv) - 5, std::to_string(lv) + " " + r.level_names[size_t(lv)], 1.3f, black);
  }
  for (int k = 1; k < int(r.oracle_level.size()); ++k)
    cv.line(sx(k - 1), ly(r.oracle_level[size_t(k - 1)]) + 3, sx(k), ly(r.oracle_level[size_t(k)]) + 3, 1.5f, grey);
  for (int k = 1; k < n; ++k)
    cv.line(sx(k - 1), ly(r.scheduled[size_t(k - 1)].level), sx(k), ly(r.scheduled[size_t(k)].level), 2.0f, blue);
  cv.text(x1 - 260, strips[0].y1 + 4, "level: scheduled (blue), oracle (grey)", 1.3f, black);

  // Strip 2: internal-resolution factor (the level's scale x the scheduler's), 0..1.
  auto syv = [&](double v) { return strips[1].y1 - (strips[1].y1 - strips[1].y0) * float(std::clamp(v, 0.0, 1.0)); };
  for (double v : {0.0, 0.5, 1.0}) {
    cv.line(x0, syv(v), x1, syv(v), 0.5f, {220, 220, 220});
    cv.text(50, syv(v) - 5, tick_label(v, 0.5), 1.3f, black);
  }
  for (int k = 1; k < n; ++k)
    cv.line(sx(k - 1), syv(r.scheduled[size_t(k - 1)].scale), sx(k), syv(r.scheduled[size_t(k)].scale), 1.5f, blue);
  cv.text(x1 - 260, strips[1].y1 + 4, "internal scale (of the output's side)", 1.3f, black);

  // Strip 3: cost per frame, ms, against the budget.
  double top = r.settings.budget_ms * 2.0;
  for (const LoadFrame& f : r.scheduled) top = std::max(top, std::min(f.cost_ms, r.settings.budget_ms * 4.0));
  const PlotAxis ax = nice_axis(top);
  auto sc = [&](double ms) { return strips[2].y1 - (strips[2].y1 - strips[2].y0) * float(std::min(ms, ax.max) / ax.max); };
  for (int i = 0; i * ax.step <= ax.max + 1e-9; ++i) {
    cv.line(x0, sc(i * ax.step), x1, sc(i * ax.step), 0.5f, {220, 220, 220});
    cv.text(40, sc(i * ax.step) - 5, tick_label(i * ax.step, ax.step), 1.3f, black);
  }
  for (int k = 0; k < n; ++k) cv.marker(sx(k), sc(r.scheduled[size_t(k)].cost_ms), Marker::Circle, 1.6f, blue, blue);
  cv.line(x0, sc(r.settings.budget_ms), x1, sc(r.settings.budget_ms), 1.5f, red, 8.0f);
  cv.text(x1 - 260, strips[2].y1 + 4, "cost per frame, ms (budget dashed)", 1.3f, black);
  for (const Strip& s : strips) cv.line(x0, s.y0, x0, s.y1, 1.0f, black);
  // Frame axis in seconds at 30 fps.
  for (int sec = 0; sec * 30 <= n; sec += 2) {
    cv.line(sx(sec * 30), strips[2].y1, sx(sec * 30), strips[2].y1 + 5, 1.0f, black);
    cv.text(sx(sec * 30) - 6, strips[2].y1 + 20, std::to_string(sec) + " s", 1.3f, black);
  }
  return cv.image();
}

}  // namespace mrgi::perf
