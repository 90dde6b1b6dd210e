// Texture decoding for glTF (image/texture_decode.h): libjpeg-turbo and libpng from memory.
// Valid files decode to RGBA8; truncated and mutated ones (single bytes changed, the kind of
// input fuzzing found stb_image writing out of bounds on) are refused or decoded, never crash;
// sizes beyond the limit are refused before allocation.
#include <gtest/gtest.h>

#include <cstdio>
#include <jpeglib.h>

#include <fstream>
#include <random>
#include <vector>

#include "capture/temp_dir.h"
#include "image/texture_decode.h"
#include "mrgi/image.h"

namespace {

std::vector<uint8_t> encode_jpeg(int w, int h) {
  jpeg_compress_struct c;
  jpeg_error_mgr e;
  c.err = jpeg_std_error(&e);
  jpeg_create_compress(&c);
  unsigned char* buf = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &buf, &size);
  c.image_width = JDIMENSION(w);
  c.image_height = JDIMENSION(h);
  c.input_components = 3;
  c.in_color_space = JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 90, TRUE);
  jpeg_start_compress(&c, TRUE);
  std::vector<uint8_t> row(size_t(w) * 3);
  while (c.next_scanline < c.image_height) {
    for (int x = 0; x < w; ++x) {
      row[size_t(x) * 3 + 0] = uint8_t(x * 255 / (w - 1));
      row[size_t(x) * 3 + 1] = uint8_t(c.next_scanline * 255 / (h - 1));
      row[size_t(x) * 3 + 2] = 128;
    }
    JSAMPROW r = row.data();
    jpeg_write_scanlines(&c, &r, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::vector<uint8_t> out(buf, buf + size);
  free(buf);
  return out;
}

void mutate_and_decode(const std::vector<uint8_t>& good, bool jpeg) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<uint8_t> bad = good;
    if (trial % 3 == 0) {
      bad.resize(size_t(rng() % bad.size()));  // truncated
    } else {
      for (int k = 0; k < 1 + trial % 4; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    }
    auto r = jpeg ? mrgi::decode_jpeg_rgba8(bad.data(), bad.size()) : mrgi::decode_png_rgba8(bad.data(), bad.size());
    if (r.ok()) {
      EXPECT_GT(r->width, 0);
      EXPECT_EQ(r->data.size(), size_t(r->width) * size_t(r->height) * 4);
    } else {
      EXPECT_FALSE(r.error().message.empty());
    }
  }
}

TEST(TextureDecode, JpegDecodesAndSurvivesMutations) {
  const std::vector<uint8_t> jpeg = encode_jpeg(64, 32);
  auto img = mrgi::decode_jpeg_rgba8(jpeg.data(), jpeg.size());
  ASSERT_TRUE(img.ok()) << img.error().message;
  EXPECT_EQ(img->width, 64);
  EXPECT_EQ(img->height, 32);
  EXPECT_NEAR(img->at(63, 0)[0], 255, 12);
  EXPECT_NEAR(img->at(0, 31)[1], 255, 12);
  EXPECT_EQ(img->at(10, 10)[3], 255);
  mutate_and_decode(jpeg, true);
  EXPECT_FALSE(mrgi::decode_jpeg_rgba8(jpeg.data(), 2).ok());
}

TEST(TextureDecode, PngDecodesAnyLayoutAndSurvivesMutations) {
  mrgi::testing::TempDir dir;
  mrgi::ImageU16 grey16(8, 4);
  for (size_t i = 0; i < grey16.data.size(); ++i) grey16.data[i] = uint16_t(i * 2000);
  ASSERT_TRUE(mrgi::write_png(dir.file("g.png"), grey16).ok());
  std::ifstream in(dir.file("g.png"), std::ios::binary);
  const std::vector<uint8_t> png((std::istreambuf_iterator<char>(in)), {});
  auto img = mrgi::decode_png_rgba8(png.data(), png.size());
  ASSERT_TRUE(img.ok()) << img.error().message;
  EXPECT_EQ(img->width, 8);
  EXPECT_EQ(img->at(3, 0)[0], uint8_t((3 * 2000) >> 8));  // 16-bit grey -> its high byte, as RGB
  EXPECT_EQ(img->at(3, 0)[2], img->at(3, 0)[0]);
  EXPECT_EQ(img->at(3, 0)[3], 255);
  mutate_and_decode(png, false);
}

TEST(TextureDecode, OversizedHeadersAreRefusedBeforeAllocating) {
  // A JPEG SOF0 header claiming 65000 x 65000 pixels.
  std::vector<uint8_t> jpeg = encode_jpeg(16, 16);
  for (size_t i = 0; i + 8 < jpeg.size(); ++i)
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xC0) {
      jpeg[i + 5] = 0xFD;
      jpeg[i + 6] = 0xE8;  // height 65000
      jpeg[i + 7] = 0xFD;
      jpeg[i + 8] = 0xE8;  // width 65000
      break;
    }
  auto r = mrgi::decode_jpeg_rgba8(jpeg.data(), jpeg.size());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("limit"), std::string::npos) << r.error().message;
}

}  // namespace
