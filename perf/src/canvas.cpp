#include "mrgi/perf/canvas.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace mrgi::perf {
namespace {

float coverage(float signed_distance) { return std::clamp(0.5f - signed_distance, 0.0f, 1.0f); }

float segment_distance(float px, float py, float x0, float y0, float x1, float y1) {
  const float dx = x1 - x0, dy = y1 - y0;
  const float len2 = dx * dx + dy * dy;
  float t = len2 > 0.0f ? ((px - x0) * dx + (py - y0) * dy) / len2 : 0.0f;
  t = std::clamp(t, 0.0f, 1.0f);
  const float ex = px - (x0 + t * dx), ey = py - (y0 + t * dy);
  return std::sqrt(ex * ex + ey * ey);
}

// Signed distance (pixels, negative inside) of point (dx, dy) relative to the marker's centre.
float marker_distance(Marker m, float dx, float dy, float r) {
  switch (m) {
    case Marker::Circle: return std::sqrt(dx * dx + dy * dy) - r;
    case Marker::Square: {
      const float s = r * 0.85f;
      return std::max(std::fabs(dx), std::fabs(dy)) - s;
    }
    case Marker::Diamond: return (std::fabs(dx) + std::fabs(dy)) / std::sqrt(2.0f) - r * 0.8f;
    case Marker::TriangleUp:
    case Marker::TriangleDown: {
      // Equilateral triangle, centroid at the origin, circumradius ~1.2 r: the maximum of the
      // three edge half-plane distances.
      const float y = m == Marker::TriangleUp ? dy : -dy;
      const float inr = r * 0.6f;  // inradius
      const float d0 = y - inr;    // bottom edge (y down)
      const float d1 = (-0.866f * dx - 0.5f * y) - inr;
      const float d2 = (0.866f * dx - 0.5f * y) - inr;
      return std::max(d0, std::max(d1, d2));
    }
    case Marker::Plus: {
      const float w = r * 0.35f;
      const float a = std::max(std::fabs(dx) - r, std::fabs(dy) - w);
      const float b = std::max(std::fabs(dy) - r, std::fabs(dx) - w);
      return std::min(a, b);
    }
    case Marker::Cross: {
      const float u = (dx + dy) * 0.7071f, v = (dx - dy) * 0.7071f, w = r * 0.35f;
      const float a = std::max(std::fabs(u) - r, std::fabs(v) - w);
      const float b = std::max(std::fabs(v) - r, std::fabs(u) - w);
      return std::min(a, b);
    }
  }
  return 1e9f;
}

}  // namespace

Canvas::Canvas(int width, int height, Rgb bg) : image_(width, height) {
  for (size_t i = 0; i < image_.pixel_count(); ++i) {
    image_.data[i * 3 + 0] = bg.r;
    image_.data[i * 3 + 1] = bg.g;
    image_.data[i * 3 + 2] = bg.b;
  }
}

void Canvas::blend(int x, int y, Rgb c, float a) {
  if (x < 0 || y < 0 || x >= image_.width || y >= image_.height || !(a > 0.0f)) return;
  a = std::min(a, 1.0f);
  uint8_t* p = image_.at(x, y);
  const uint8_t src[3] = {c.r, c.g, c.b};
  for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(p[k] + (src[k] - p[k]) * a));
}

void Canvas::fill_rect(float x0, float y0, float x1, float y1, Rgb c, float alpha) {
  if (x1 < x0) std::swap(x0, x1);
  if (y1 < y0) std::swap(y0, y1);
  const int ix0 = int(std::floor(x0)), ix1 = int(std::ceil(x1)), iy0 = int(std::floor(y0)), iy1 = int(std::ceil(y1));
  for (int y = iy0; y < iy1; ++y) {
    const float cy = std::min(float(y + 1), y1) - std::max(float(y), y0);
    for (int x = ix0; x < ix1; ++x) {
      const float cx = std::min(float(x + 1), x1) - std::max(float(x), x0);
      blend(x, y, c, alpha * std::clamp(cx, 0.0f, 1.0f) * std::clamp(cy, 0.0f, 1.0f));
    }
  }
}

void Canvas::line(float x0, float y0, float x1, float y1, float width, Rgb c, float dash) {
  const float len = std::hypot(x1 - x0, y1 - y0);
  if (dash > 0.0f && len > dash) {
    const float step = dash * 1.5f;
    for (float s = 0.0f; s < len; s += step) {
      const float e = std::min(s + dash, len);
      line(x0 + (x1 - x0) * s / len, y0 + (y1 - y0) * s / len, x0 + (x1 - x0) * e / len,
           y0 + (y1 - y0) * e / len, width, c, 0.0f);
    }
    return;
  }
  const float h = width * 0.5f;
  const int bx0 = int(std::floor(std::min(x0, x1) - h - 1)), bx1 = int(std::ceil(std::max(x0, x1) + h + 1));
  const int by0 = int(std::floor(std::min(y0, y1) - h - 1)), by1 = int(std::ceil(std::max(y0, y1) + h + 1));
  for (int y = std::max(by0, 0); y <= std::min(by1, image_.height - 1); ++y)
    for (int x = std::max(bx0, 0); x <= std::min(bx1, image_.width - 1); ++x)
      blend(x, y, c, coverage(segment_distance(x + 0.5f, y + 0.5f, x0, y0, x1, y1) - h));
}

void Canvas::marker(float cx, float cy, Marker m, float r, Rgb fill, Rgb outline) {
  const int x0 = int(std::floor(cx - 2 * r - 2)), x1 = int(std::ceil(cx + 2 * r + 2));
  const int y0 = int(std::floor(cy - 2 * r - 2)), y1 = int(std::ceil(cy + 2 * r + 2));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const float d = marker_distance(m, x + 0.5f - cx, y + 0.5f - cy, r);
      // Outline: a ring of 1.2 px straddling the edge, then the fill inside it.
      blend(x, y, outline, coverage(std::fabs(d + 0.3f) - 0.6f));
      blend(x, y, fill, coverage(d + 0.9f));
    }
}

float Canvas::text_width(const std::string& s, float scale) {
  std::vector<char> buf(s.begin(), s.end());
  buf.push_back('\0');
  return float(stb_easy_font_width(buf.data())) * scale;
}

void Canvas::text(float x, float y, const std::string& s, float scale, Rgb c, bool vertical) {
  std::vector<char> buf(s.begin(), s.end());
  buf.push_back('\0');
  // Each glyph is at most a dozen quads of 4 vertices x 16 bytes.
  std::vector<char> quads(buf.size() * 1024 + 64);
  const int n = stb_easy_font_print(0.0f, 0.0f, buf.data(), nullptr, quads.data(), int(quads.size()));
  for (int q = 0; q < n; ++q) {
    const float* v = reinterpret_cast<const float*>(quads.data() + size_t(q) * 64);
    // Each quad is axis-aligned: vertex 0 is the top-left corner, vertex 2 the bottom-right.
    const float u0 = v[0] * scale, v0 = v[1] * scale, u1 = v[8] * scale, v1 = v[9] * scale;
    if (!vertical) {
      fill_rect(x + u0, y + v0, x + u1, y + v1, c);
    } else {
      // (u, v) -> (x + v, y - u): glyph x runs up the image, glyph y runs right.
      fill_rect(x + v0, y - u1, x + v1, y - u0, c);
    }
  }
}

PlotAxis nice_axis(double data_max) {
  if (!(data_max > 0.0) || !std::isfinite(data_max)) data_max = 1.0;
  const double target = data_max * 1.08;
  const double raw = target / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  return PlotAxis{std::ceil(target / step - 1e-9) * step, step};
}

std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : int(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 6), v);
  return buf;
}

}  // namespace mrgi::perf
