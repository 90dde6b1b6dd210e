// A small RGB rasteriser for the bench's plots: coverage-antialiased lines and markers (coverage
// from the distance of each pixel centre to the shape), axis-aligned rectangles with fractional
// edges, and text from stb_easy_font's quads (scaled, optionally turned 90 degrees).
#pragma once
#include <cstdint>
#include <string>
#include <utility>

#include "mrgi/image.h"

namespace mrgi::perf {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
};

// The plots' colours (matplotlib's tab10 order), for series told apart by colour.
inline constexpr Rgb kPalette[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                   {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                   {188, 189, 34},  {23, 190, 207}};

// An axis from 0 to a "nice" maximum above data_max (with 8 % room) in 4..8 ticks of step 1, 2
// or 5 x 10^k; a tick's label with as many decimals as the step needs.
struct PlotAxis {
  double max = 1.0, step = 0.2;
};
PlotAxis nice_axis(double data_max);
std::string tick_label(double v, double step);

enum class Marker { Circle, Square, TriangleUp, Diamond, Plus, Cross, TriangleDown };

class Canvas {
 public:
  Canvas(int width, int height, Rgb background);
  // Draws over an existing picture (labels on a composite).
  explicit Canvas(ImageRGB8 image) : image_(std::move(image)) {}
  const ImageRGB8& image() const { return image_; }

  // Mixes `c` into pixel (x, y) with weight alpha in [0, 1]; outside pixels are ignored.
  void blend(int x, int y, Rgb c, float alpha);
  void fill_rect(float x0, float y0, float x1, float y1, Rgb c, float alpha = 1.0f);
  // A segment `width` pixels wide with round caps; dash > 0 draws dashes of that length (and
  // gaps of dash/2) along it.
  void line(float x0, float y0, float x1, float y1, float width, Rgb c, float dash = 0.0f);
  // A filled marker of radius r (pixels) with a 1-pixel outline in `outline`.
  void marker(float cx, float cy, Marker m, float r, Rgb fill, Rgb outline);

  // Text with its top-left corner at (x, y); scale 1 is stb_easy_font's ~7 px cap height.
  // vertical: turned 90 degrees anticlockwise (reads bottom to top), (x, y) is then bottom-left.
  void text(float x, float y, const std::string& s, float scale, Rgb c, bool vertical = false);
  static float text_width(const std::string& s, float scale);
  static float text_height(float scale) { return 7.0f * scale; }

 private:
  ImageRGB8 image_;
};

}  // namespace mrgi::perf
