// The bench's side-by-side images (mrgi/perf/sample_sheet.h): area-averaged thumbnails, and a
// sheet that puts the inputs in the first row and each technique's levels in a row of their own.
#include <gtest/gtest.h>

#include <climits>

#include "mrgi/perf/sample_sheet.h"

namespace perf = mrgi::perf;
using mrgi::ImageRGB8;

namespace {

ImageRGB8 solid(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  ImageRGB8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = r, p[1] = g, p[2] = b;
    }
  return img;
}

struct Box {
  int x0 = INT_MAX, y0 = INT_MAX, x1 = -1, y1 = -1;
  long count = 0;
};

// Where the pixels of exactly one colour lie in `img`.
Box find(const ImageRGB8& img, uint8_t r, uint8_t g, uint8_t b) {
  Box box;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      if (p[0] != r || p[1] != g || p[2] != b) continue;
      box.x0 = std::min(box.x0, x), box.y0 = std::min(box.y0, y);
      box.x1 = std::max(box.x1, x), box.y1 = std::max(box.y1, y);
      ++box.count;
    }
  return box;
}

perf::BenchEntry entry(const std::string& technique, int level, uint8_t shade) {
  perf::BenchEntry e;
  e.scene = "room";
  e.technique = technique;
  e.level = level;
  e.level_name = level == 0 ? "high" : "fast";
  e.has_reference = true;
  e.error.all.rde = 0.25;
  e.sustained_ms = 20.0;
  e.sample = solid(perf::kSampleWidth, 192, shade, 0, 200);
  e.sample_frame = 3;
  return e;
}

}  // namespace

TEST(SampleSheet, ThumbnailAveragesBoxesAndKeepsTheAspect) {
  // A 2 x 2 checkerboard of black and white averages to mid grey at half the size.
  ImageRGB8 checker(640, 480);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      for (int c = 0; c < 3; ++c) checker.at(x, y)[c] = ((x + y) % 2) ? 255 : 0;
  const ImageRGB8 half = perf::thumbnail(checker, 320);
  ASSERT_EQ(half.width, 320);
  ASSERT_EQ(half.height, 240);
  EXPECT_NEAR(half.at(100, 100)[0], 128, 1);
  // 640 x 480 to the sheet's width: 256 x 192; the left half red stays red, the right blue.
  ImageRGB8 split = solid(640, 480, 255, 0, 0);
  for (int y = 0; y < 480; ++y)
    for (int x = 320; x < 640; ++x) split.at(x, y)[0] = 0, split.at(x, y)[2] = 255;
  const ImageRGB8 t = perf::thumbnail(split, perf::kSampleWidth);
  EXPECT_EQ(t.width, 256);
  EXPECT_EQ(t.height, 192);
  EXPECT_EQ(t.at(10, 50)[0], 255);
  EXPECT_EQ(t.at(245, 50)[2], 255);
  // An image no wider than asked for is copied.
  const ImageRGB8 small = solid(100, 50, 1, 2, 3);
  EXPECT_EQ(perf::thumbnail(small, 256).data, small.data);
}

TEST(SampleSheet, InputsFirstThenOneRowPerTechniqueWithItsLevelsInOrder) {
  perf::BenchResult r;
  r.entries = {entry("baseline", 0, 10), entry("baseline", 1, 20), entry("dir", 0, 30), entry("dir", 1, 40)};
  r.samples.push_back(perf::SceneSample{"room", 3, solid(256, 192, 250, 10, 10), solid(256, 192, 10, 250, 10)});
  auto sheet = perf::render_sample_sheet(r, "room");
  ASSERT_TRUE(sheet.has_value());
  const Box camera = find(*sheet, 250, 10, 10), reference = find(*sheet, 10, 250, 10);
  Box level[4];
  for (int i = 0; i < 4; ++i) level[i] = find(*sheet, uint8_t(10 * (i + 1)), 0, 200);
  // Every image is on the sheet whole (text is drawn only above each image).
  for (const Box& b : {camera, reference, level[0], level[1], level[2], level[3]}) EXPECT_EQ(b.count, 256L * 192L);
  EXPECT_LT(camera.x1, reference.x0);                      // the inputs side by side
  EXPECT_LT(camera.y1, level[0].y0);                       // above the techniques
  EXPECT_EQ(level[0].y0, level[1].y0);                     // a technique's levels in one row,
  EXPECT_LT(level[0].x1, level[1].x0);                     //   best first
  EXPECT_LT(level[1].y1, level[2].y0);                     // the next technique below
  EXPECT_EQ(level[0].x0, level[2].x0);
  EXPECT_EQ(camera.x0, level[0].x0);
}

TEST(SampleSheet, NothingForASceneWithoutSamplesAndAFileNameForEveryScene) {
  perf::BenchResult r;
  r.entries = {entry("baseline", 0, 10)};
  r.entries[0].sample_frame = -1;  // no reference: nothing kept
  r.entries[0].sample = ImageRGB8{};
  EXPECT_FALSE(perf::render_sample_sheet(r, "room").has_value());
  EXPECT_FALSE(perf::render_sample_sheet(r, "another").has_value());
  EXPECT_EQ(perf::sample_sheet_path("room"), "images/room.png");
  EXPECT_EQ(perf::sample_sheet_path("light/courtyard_down"), "images/light-courtyard_down.png");
}

TEST(SampleSheet, LongLabelsStayInsideTheirCells) {
  perf::BenchResult r;
  r.entries = {entry("baseline", 0, 10), entry("baseline", 1, 20)};
  for (perf::BenchEntry& e : r.entries) e.level_name += " internal_scale=0.75 shadow_map_size=2048 pcf_radius=1";
  auto sheet = perf::render_sample_sheet(r, "room");
  ASSERT_TRUE(sheet.has_value());
  const Box left = find(*sheet, 10, 0, 200), right = find(*sheet, 20, 0, 200);
  ASSERT_LT(left.x1, right.x0);
  // The columns between the two cells hold nothing but the background, from the cells' labels
  // (two lines above each image) down; the sheet's title above them spans the sheet.
  for (int y = left.y0 - 40; y < sheet->height; ++y)
    for (int x = left.x1 + 1; x < right.x0; ++x) {
      const uint8_t* p = sheet->at(x, y);
      ASSERT_TRUE(p[0] == 255 && p[1] == 255 && p[2] == 255) << "ink at " << x << "," << y;
    }
}
