#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "capture/temp_dir.h"
#include "common/shared_data.h"
#include "image/srgb.h"
#include "mrgi/image.h"

namespace mrgi {
namespace {

using testing::TempDir;

template <class T, int C>
Image<T, C> gradient(int w, int h, int mul) {
  Image<T, C> img(w, h);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = T((i * size_t(mul) + 7) % 65536);
  return img;
}

TEST(PngIo, RoundTripsEveryFormatBitExactly) {
  TempDir dir;
  const auto rgb = gradient<uint8_t, 3>(13, 7, 5);
  const auto rgba = gradient<uint8_t, 4>(5, 9, 3);
  const auto u16 = gradient<uint16_t, 1>(11, 4, 4099);
  const auto u8 = gradient<uint8_t, 1>(3, 17, 11);
  ASSERT_TRUE(write_png(dir.file("rgb.png"), rgb).ok());
  ASSERT_TRUE(write_png(dir.file("rgba.png"), rgba).ok());
  ASSERT_TRUE(write_png(dir.file("u16.png"), u16).ok());
  ASSERT_TRUE(write_png(dir.file("u8.png"), u8).ok());
  auto rgb2 = load_png_rgb8(dir.file("rgb.png"));
  auto rgba2 = load_png_rgba8(dir.file("rgba.png"));
  auto u162 = load_png_u16(dir.file("u16.png"));
  auto u82 = load_png_u8(dir.file("u8.png"));
  ASSERT_TRUE(rgb2.ok() && rgba2.ok() && u162.ok() && u82.ok());
  EXPECT_EQ(rgb2->width, 13);
  EXPECT_EQ(rgb2->height, 7);
  EXPECT_EQ(rgb2->data, rgb.data);
  EXPECT_EQ(rgba2->data, rgba.data);
  EXPECT_EQ(u162->width, 11);
  EXPECT_EQ(u162->data, u16.data);  // also proves the 16-bit byte order is right
  EXPECT_GT(*std::max_element(u162->data.begin(), u162->data.end()), 255);
  EXPECT_EQ(u82->data, u8.data);
  // No temporary file is left behind by the write-then-rename.
  EXPECT_FALSE(std::filesystem::exists(dir.file("rgb.png.tmp")));
}

// PngEffort::Small (zlib 9, for stored data) keeps the pixels and never makes a file larger than
// Fast on data that compresses (a smooth gradient with a little deterministic noise).
TEST(PngIo, SmallEffortKeepsPixelsAndIsNoLarger) {
  TempDir dir;
  ImageU16 depth(160, 120);
  for (size_t i = 0; i < depth.data.size(); ++i)
    depth.data[i] = uint16_t(4000 + (i % 160) * 10 + (i / 160) * 3 + (i * 2654435761u >> 28));
  ASSERT_TRUE(write_png(dir.file("fast.png"), depth, PngEffort::Fast).ok());
  ASSERT_TRUE(write_png(dir.file("small.png"), depth, PngEffort::Small).ok());
  auto fast = load_png_u16(dir.file("fast.png"));
  auto small = load_png_u16(dir.file("small.png"));
  ASSERT_TRUE(fast.ok() && small.ok());
  EXPECT_EQ(fast->data, depth.data);
  EXPECT_EQ(small->data, depth.data);
  EXPECT_LE(std::filesystem::file_size(dir.file("small.png")),
            std::filesystem::file_size(dir.file("fast.png")));
}

TEST(PngIo, RgbaLoaderGivesRgbAnOpaqueAlpha) {
  TempDir dir;
  ImageRGB8 rgb(2, 1);
  rgb.data = {1, 2, 3, 4, 5, 6};
  ASSERT_TRUE(write_png(dir.file("c.png"), rgb).ok());
  auto rgba = load_png_rgba8(dir.file("c.png"));
  ASSERT_TRUE(rgba.ok());
  EXPECT_EQ(rgba->data, (std::vector<uint8_t>{1, 2, 3, 255, 4, 5, 6, 255}));
}

TEST(PngIo, ColourLoaderRefuses16BitAndGrey) {
  TempDir dir;
  ASSERT_TRUE(write_png(dir.file("d.png"), ImageU16(4, 4, 1000)).ok());
  ASSERT_TRUE(write_png(dir.file("m.png"), ImageU8(4, 4, 9)).ok());
  EXPECT_ERROR(load_png_rgb8(dir.file("d.png")), BadInput, "d.png", "16-bit grey", "expected 8-bit RGB");
  EXPECT_ERROR(load_png_rgb8(dir.file("m.png")), BadInput, "m.png", "8-bit grey", "expected 8-bit RGB");
}

TEST(PngIo, DepthLoaderRefuses8Bit) {
  TempDir dir;
  ASSERT_TRUE(write_png(dir.file("m.png"), ImageU8(4, 3, 9)).ok());
  ASSERT_TRUE(write_png(dir.file("c.png"), ImageRGB8(4, 3, 9)).ok());
  EXPECT_ERROR(load_png_u16(dir.file("m.png")), BadInput, "m.png", "8-bit grey (4x3)", "expected 16-bit grey");
  EXPECT_ERROR(load_png_u16(dir.file("c.png")), BadInput, "c.png", "8-bit RGB", "16-bit");
  EXPECT_ERROR(load_png_u8(dir.file("c.png")), BadInput, "c.png", "8-bit RGB", "expected 8-bit grey");
}

TEST(PngIo, MissingAndCorruptFilesAreNamed) {
  TempDir dir;
  EXPECT_ERROR(load_png_rgb8(dir.file("none.png")), NotFound, "none.png", "does not exist");
  testing::write_text(dir.file("junk.png"), "this is not a png");
  EXPECT_ERROR(load_png_rgb8(dir.file("junk.png")), BadInput, "junk.png", "not a PNG");
  // A real PNG cut in half: libpng's error is reported, nothing crashes.
  ASSERT_TRUE(write_png(dir.file("full.png"), gradient<uint8_t, 3>(64, 64, 13)).ok());
  const auto size = std::filesystem::file_size(dir.file("full.png"));
  std::filesystem::resize_file(dir.file("full.png"), size / 2);
  EXPECT_ERROR(load_png_rgb8(dir.file("full.png")), BadInput, "full.png", "cannot decode PNG");
}

TEST(PngIo, WriterRefusesEmptyImage) {
  TempDir dir;
  EXPECT_ERROR(write_png(dir.file("e.png"), ImageRGB8{}), BadUsage, "e.png", "empty");
  EXPECT_FALSE(std::filesystem::exists(dir.file("e.png")));
}

TEST(HdrIo, ExrRoundTripsFloatsExactly) {
  TempDir dir;
  ImageRGBF img(6, 3);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i) * 0.37f + 1e-3f * float(i * i);
  img.data[4] = 12345.678f;
  ASSERT_TRUE(write_exr(dir.file("e.exr"), img).ok());
  auto back = load_hdr_image(dir.file("e.exr"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, 6);
  EXPECT_EQ(back->height, 3);
  EXPECT_EQ(back->data, img.data);
}

// fuzz_hdr (10-minute run): a header line of NUL bytes ends stb's header (it reads the line as
// empty), so the run-length check must start where stb does; this 68-byte file hung stb.
TEST(HdrIo, RunLengthCheckStartsWhereStbReadsThePixels) {
  TempDir dir;
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n";
  hdr += std::string("\0\0\n", 3);
  hdr += "-Y 2 +X 8\n";
  hdr += std::string("\x02\x02\x00\x08\x88\x64\x88\x49\x00\x00\x00\x00\x00\x00\x00\x08\x09\x00\x00\x00\x6d", 21);
  testing::write_text(dir.file("nul.hdr"), hdr);
  EXPECT_ERROR(load_hdr_image(dir.file("nul.hdr")), BadInput, "nul.hdr", "scanline");
}

// fuzz_hdr (10-minute run): an OpenEXR header asking for a 4980740 x 2 strip was read whole.
// Every side is bounded now, as the Radiance loader's size, before any pixel is read.
TEST(HdrIo, ExrStripsWiderThanTheLimitAreRefused) {
  TempDir dir;
  ImageRGBF strip(16385, 1, 0.25f);
  ASSERT_TRUE(write_exr(dir.file("strip.exr"), strip).ok());
  EXPECT_ERROR(load_hdr_image(dir.file("strip.exr")), BadInput, "strip.exr", "16385x1", "16384 a side");
  ImageRGBF widest(16384, 1, 0.25f);
  ASSERT_TRUE(write_exr(dir.file("widest.exr"), widest).ok());
  EXPECT_TRUE(load_hdr_image(dir.file("widest.exr")).ok());
}

TEST(HdrIo, NonFiniteRadianceIsRefusedNamingFileAndPixel) {
  TempDir dir;
  ImageRGBF img(4, 2, 0.5f);
  img.at(1, 1)[2] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_ERROR(write_exr(dir.file("n.exr"), img), BadInput, "n.exr", "pixel (1, 1)", "NaN", "finite");
}

TEST(HdrIo, PngIsDecodedFromSrgbToLinear) {
  TempDir dir;
  ImageRGB8 png(3, 1);
  png.data = {0, 128, 255, 255, 255, 255, 10, 20, 30};
  ASSERT_TRUE(write_png(dir.file("env.png"), png).ok());
  auto lin = load_hdr_image(dir.file("env.png"));
  ASSERT_TRUE(lin.ok());
  EXPECT_FLOAT_EQ(lin->data[0], 0.0f);
  EXPECT_NEAR(lin->data[1], 0.2158605f, 1e-6f);  // sRGB 128 -> 0.2158605 linear
  EXPECT_FLOAT_EQ(lin->data[2], 1.0f);
  EXPECT_NEAR(lin->data[6], 10.0f / 255.0f / 12.92f, 1e-7f);  // linear segment of the curve
}

TEST(HdrIo, RadianceHdrFromStb) {
  TempDir dir;
  // A 2x1 uncompressed RGBE file: (128,64,32,129) = (1, 0.5, 0.25) and (128,128,128,128) = 0.5.
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  hdr += std::string("\x80\x40\x20\x81\x80\x80\x80\x80", 8);
  testing::write_text(dir.file("e.hdr"), hdr);
  auto img = load_hdr_image(dir.file("e.hdr"));
  ASSERT_TRUE(img.ok()) << img.error().message;
  ASSERT_EQ(img->width, 2);
  EXPECT_NEAR(img->data[0], 1.0f, 1e-2f);
  EXPECT_NEAR(img->data[1], 0.5f, 1e-2f);
  EXPECT_NEAR(img->data[2], 0.25f, 1e-2f);
  EXPECT_NEAR(img->data[3], 0.5f, 1e-2f);
}

// Flat (not run-length) pixel data cut short: stb would fill the missing rows with zeros; the
// loader refuses it naming the rows and bytes, for a narrow image (always flat) and for a wide one
// whose first scanline lacks the run-length marker. Whole files still load.
TEST(HdrIo, FlatRadianceDataCutShortIsRefused) {
  TempDir dir;
  const std::string narrow = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n";
  const std::string pixel("\x80\x40\x20\x81", 4);
  testing::write_text(dir.file("whole.hdr"), narrow + pixel + pixel + pixel + pixel);
  EXPECT_TRUE(load_hdr_image(dir.file("whole.hdr")).ok());
  testing::write_text(dir.file("half.hdr"), narrow + pixel + pixel);
  EXPECT_ERROR(load_hdr_image(dir.file("half.hdr")), BadInput, "half.hdr", "ends early", "need 16 bytes",
               "has 8");
  const std::string wide = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 16\n";
  std::string rows;
  for (int i = 0; i < 16 * 4; ++i) rows += pixel;
  testing::write_text(dir.file("wide.hdr"), wide + rows);
  EXPECT_TRUE(load_hdr_image(dir.file("wide.hdr")).ok());
  testing::write_text(dir.file("wide_cut.hdr"), wide + rows.substr(0, rows.size() / 2));
  EXPECT_ERROR(load_hdr_image(dir.file("wide_cut.hdr")), BadInput, "wide_cut.hdr", "ends early", "rows 0..3");
}

// A 2 KB .hdr whose header asks for 120 GB is refused before allocating.
TEST(HdrIo, RadianceHeaderBeyondTheSizeLimitIsRefused) {
  TempDir dir;
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";
  hdr += std::string(2000, '\x80');
  testing::write_text(dir.file("huge.hdr"), hdr);
  EXPECT_ERROR(load_hdr_image(dir.file("huge.hdr")), BadInput, "huge.hdr", "100000x100000", "limit");
}

// The shared maps are DWAB-compressed half floats (tinyexr cannot decode them).
// fuzz_hdr (10-minute run): a 38-byte file named .hdr that stb's generic loader read as a TGA
// header kept it busy for minutes; only a file with the Radiance signature reaches stb now.
TEST(HdrIo, FilesWithoutTheRadianceSignatureAreRefusedBeforeStb) {
  testing::TempDir dir;
  std::string tga("\xf5\x00\x0b\xdf\xdf\x00\x00\x61\x00\x00\x61\x30\x00\x04\x8b\x80"
                  "\x20\x38\x0a\x02\x02\x5f\x68\xa3\x5c\x31\x56\x00\x00\x00\x08\x88"
                  "\xdf\xdf\xdf\xdf\xdf\x41", 38);
  testing::write_text(dir.file("tga.hdr"), tga);
  EXPECT_ERROR(load_hdr_image(dir.file("tga.hdr")), BadInput, "tga.hdr", "#?RADIANCE");
  testing::write_text(dir.file("png_bytes.hdr"), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_ERROR(load_hdr_image(dir.file("png_bytes.hdr")), BadInput, "png_bytes.hdr", "signature");
}

TEST(HdrIo, RealDwabEnvironmentMapsLoadFinite) {
  MRGI_SKIP_WITHOUT_SHARED(mrgi::test::shared_data("env"));
  for (const char* name : {"interior.exr", "courtyard.exr"}) {
    auto img = load_hdr_image(mrgi::test::shared_data("env/") + name);
    ASSERT_TRUE(img.ok()) << img.error().message;
    EXPECT_EQ(img->width, 2 * img->height) << name;  // equirectangular
    double sum = 0, peak = 0;
    for (float v : img->data) {
      sum += v;
      peak = std::max(peak, double(v));
    }
    EXPECT_GT(sum / double(img->data.size()), 0.01) << name;
    EXPECT_GT(peak, 1.0) << name;  // real HDR: the sun or lamps exceed display white
    // DWAB rings below zero in the file; the loader clamps radiance to >= 0.
    EXPECT_GE(*std::min_element(img->data.begin(), img->data.end()), 0.0f) << name;
  }
}

TEST(HdrIo, CorruptExrIsRefused) {
  TempDir dir;
  testing::write_text(dir.file("bad.exr"), std::string("\x76\x2f\x31\x01garbage", 11));
  EXPECT_ERROR(load_hdr_image(dir.file("bad.exr")), BadInput, "bad.exr", "cannot decode OpenEXR");
}

TEST(HdrIo, UnknownExtensionAndMissingFile) {
  TempDir dir;
  testing::write_text(dir.file("e.jpg"), "x");
  EXPECT_ERROR(load_hdr_image(dir.file("e.jpg")), BadInput, "e.jpg", ".exr, .hdr or .png");
  EXPECT_ERROR(load_hdr_image(dir.file("none.exr")), NotFound, "none.exr");
}

TEST(Srgb, CurveRoundTripsEveryCode) {
  for (int i = 0; i < 256; ++i)
    EXPECT_EQ(linear_to_srgb8(srgb8_to_linear_table()[size_t(i)]), i);
  EXPECT_EQ(linear_to_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
}

}  // namespace
}  // namespace mrgi
