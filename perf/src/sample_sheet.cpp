#include "mrgi/perf/sample_sheet.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "mrgi/perf/canvas.h"

namespace mrgi::perf {
// A namespace of its own: the unity build (MRGI_UNITY_LIBS) puts this file beside the plots,
// whose anonymous namespaces hold names like these.
namespace sheet {

constexpr int kMargin = 12, kGap = 10, kLabelHeight = 34;
constexpr float kTextScale = 1.4f;
constexpr Rgb kBackground{255, 255, 255}, kInk{30, 30, 30}, kMuted{90, 90, 90};

template <int C>
ImageRGB8 box_average(const Image<uint8_t, C>& src, int width) {
  if (src.width <= 0 || src.height <= 0) return ImageRGB8{};
  const int w = std::min(width, src.width);
  const int h = std::max(1, int(double(src.height) * w / src.width + 0.5));
  ImageRGB8 out(w, h);
  for (int y = 0; y < h; ++y) {
    const int y0 = int(int64_t(y) * src.height / h), y1 = std::max(y0 + 1, int(int64_t(y + 1) * src.height / h));
    for (int x = 0; x < w; ++x) {
      const int x0 = int(int64_t(x) * src.width / w), x1 = std::max(x0 + 1, int(int64_t(x + 1) * src.width / w));
      uint32_t sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx)
          for (int c = 0; c < 3; ++c) sum[c] += src.at(sx, sy)[c];
      const uint32_t n = uint32_t((y1 - y0) * (x1 - x0));
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = uint8_t((sum[c] + n / 2) / n);
    }
  }
  return out;
}

struct Cell {
  const ImageRGB8* image = nullptr;
  std::string title, figures;
};

// A label within the cell's width: drawn smaller where it is long (a sweep's entry names its
// knob values), cut with ".." where even that does not fit, so neighbours never overlap.
void draw_label(Canvas& canvas, float x, float y, std::string s, Rgb colour) {
  const float width = float(kSampleWidth) - 4.0f;
  float scale = kTextScale;
  if (Canvas::text_width(s, scale) > width) scale = std::max(1.0f, scale * width / Canvas::text_width(s, scale));
  while (s.size() > 2 && Canvas::text_width(s, scale) > width) s = s.substr(0, s.size() - 3) + "..";
  canvas.text(x, y, s, scale, colour);
}

void draw_cell(Canvas& canvas, int x, int y, const Cell& cell) {
  draw_label(canvas, float(x), float(y), cell.title, kInk);
  if (!cell.figures.empty())
    draw_label(canvas, float(x), float(y) + Canvas::text_height(kTextScale) + 5.0f, cell.figures, kMuted);
  const ImageRGB8& img = *cell.image;
  const int top = y + kLabelHeight;
  for (int py = 0; py < img.height; ++py)
    for (int px = 0; px < img.width; ++px) {
      const uint8_t* p = img.at(px, py);
      canvas.blend(x + px, top + py, Rgb{p[0], p[1], p[2]}, 1.0f);
    }
}

std::string figures_of(const BenchEntry& e) {
  char buf[96];
  if (e.has_reference)
    std::snprintf(buf, sizeof buf, "RDE %.3f, %.1f ms", e.error.all.rde, e.sustained_ms);
  else
    std::snprintf(buf, sizeof buf, "%.1f ms", e.sustained_ms);
  return buf;
}

}  // namespace sheet

ImageRGB8 thumbnail(const ImageRGB8& image, int width) { return sheet::box_average(image, width); }
ImageRGB8 thumbnail(const ImageRGBA8& image, int width) { return sheet::box_average(image, width); }

std::string sample_sheet_path(const std::string& scene) {
  std::string name = scene;
  std::replace(name.begin(), name.end(), '/', '-');
  return "images/" + name + ".png";
}

std::optional<ImageRGB8> render_sample_sheet(const BenchResult& result, const std::string& scene) {
  // Rows: the inputs, then one per technique in the run's order, its entries in level order.
  std::vector<std::vector<sheet::Cell>> rows;
  std::vector<std::string> techniques;
  int sample_frame = -1;
  for (const BenchEntry& e : result.entries) {
    if (e.scene != scene || e.sample_frame < 0 || e.sample.width == 0) continue;
    if (sample_frame < 0) sample_frame = e.sample_frame;
    auto t = std::find(techniques.begin(), techniques.end(), e.technique);
    if (t == techniques.end()) {
      techniques.push_back(e.technique);
      rows.emplace_back();
      t = techniques.end() - 1;
    }
    rows[size_t(t - techniques.begin())].push_back(
        sheet::Cell{&e.sample, e.technique + " " + std::to_string(e.level) + " " + e.level_name, sheet::figures_of(e)});
  }
  if (rows.empty()) return std::nullopt;
  const SceneSample* inputs = nullptr;
  for (const SceneSample& s : result.samples)
    if (s.scene == scene && s.frame == sample_frame) inputs = &s;
  if (inputs) {
    rows.insert(rows.begin(), std::vector<sheet::Cell>{
                                  sheet::Cell{&inputs->camera, "camera, frame " + std::to_string(sample_frame), ""},
                                  sheet::Cell{&inputs->reference, "reference", "what RDE compares with"}});
  }
  size_t columns = 0;
  int cell_height = 0;
  for (const auto& row : rows) {
    columns = std::max(columns, row.size());
    for (const sheet::Cell& c : row) cell_height = std::max(cell_height, c.image->height);
  }
  const int title_height = 30, margin = sheet::kMargin, gap = sheet::kGap;
  const int width = 2 * margin + int(columns) * kSampleWidth + int(columns - 1) * gap;
  const int row_height = sheet::kLabelHeight + cell_height + gap;
  Canvas canvas(width, margin + title_height + int(rows.size()) * row_height + margin, sheet::kBackground);
  canvas.text(float(margin), float(margin), scene + ": the same frame from every technique level", 2.0f, sheet::kInk);
  for (size_t r = 0; r < rows.size(); ++r)
    for (size_t c = 0; c < rows[r].size(); ++c)
      sheet::draw_cell(canvas, margin + int(c) * (kSampleWidth + gap), margin + title_height + int(r) * row_height,
                       rows[r][c]);
  return canvas.image();
}

}  // namespace mrgi::perf
