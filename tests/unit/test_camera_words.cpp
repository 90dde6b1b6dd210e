// The camera's colour upload as one word a pixel (recon/reconstruction.h kColorWordBytes): the
// host's expansion of an RGB8 frame into the words, the words back into RGBA8 pixels
// (compose/compose.h camera_words_to_rgba8), and the host's reader of the camera
// (light/camera_color.h) taking the same pixels from the words as from the RGB8 rows.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "compose/compose.h"
#include "frame/camera_view.h"
#include "light/camera_color.h"
#include "recon/reconstruction.h"

namespace mrgi {
namespace {

std::vector<uint8_t> rgb_pattern(size_t pixels) {
  std::vector<uint8_t> rgb(pixels * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t((i * 37 + 11) & 0xff);
  return rgb;
}

TEST(CameraWords, EveryPixelIsItsThreeBytesWithTheTopByteZero) {
  for (size_t pixels : {size_t(1), size_t(2), size_t(5), size_t(16), size_t(17), size_t(640 * 480)}) {
    SCOPED_TRACE(pixels);
    // Exactly the frame's bytes: nothing past them may be read (the last pixel is copied byte-wise).
    const std::vector<uint8_t> rgb = rgb_pattern(pixels);
    std::vector<uint32_t> words(pixels, 0xdeadbeefu);
    recon::rgb8_to_color_words(rgb.data(), pixels, words.data());
    for (size_t i = 0; i < pixels; ++i) {
      const uint32_t want = uint32_t(rgb[3 * i]) | uint32_t(rgb[3 * i + 1]) << 8 | uint32_t(rgb[3 * i + 2]) << 16;
      ASSERT_EQ(words[i], want) << "pixel " << i;
    }
  }
}

TEST(CameraWords, TheUploadHoldsWholeGroupsOfSixteenPixels) {
  EXPECT_EQ(recon::color_upload_bytes(0), 0u);
  EXPECT_EQ(recon::color_upload_bytes(1), 64u);
  EXPECT_EQ(recon::color_upload_bytes(16), 64u);
  EXPECT_EQ(recon::color_upload_bytes(17), 128u);
  EXPECT_EQ(recon::color_upload_bytes(640 * 480), 640u * 480u * 4u);
}

TEST(CameraWords, WordsBackToRgba8AreTheFramesPixelsOpaque) {
  const size_t pixels = 33;
  const std::vector<uint8_t> rgb = rgb_pattern(pixels);
  std::vector<uint32_t> words(pixels);
  recon::rgb8_to_color_words(rgb.data(), pixels, words.data());
  words[3] |= 0x7f000000u;  // whatever the top byte holds (an app image's alpha) is not colour
  std::vector<uint8_t> rgba(pixels * 4);
  compose::camera_words_to_rgba8(words.data(), pixels, rgba.data());
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 4; ++c) ASSERT_EQ(rgba[4 * i + c], c < 3 ? rgb[3 * i + c] : 255) << "pixel " << i << " channel " << c;
}

TEST(CameraWords, TheHostsReaderTakesTheSamePixelsFromWordsAsFromRows) {
  const int w = 7, h = 5;
  const std::vector<uint8_t> rgb = rgb_pattern(size_t(w) * h);
  std::vector<uint32_t> words(size_t(w) * h);
  recon::rgb8_to_color_words(rgb.data(), words.size(), words.data());
  frame::CameraView rows, upload;
  rows.rgb = rgb.data();
  upload.rgb = reinterpret_cast<const uint8_t*>(words.data());
  upload.rgb_stride = int(recon::kColorWordBytes);
  rows.color_width = upload.color_width = w;
  rows.color_height = upload.color_height = h;
  const light::CameraColor a(rows), b(upload);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) ASSERT_EQ(a.at(x, y), b.at(x, y)) << x << ", " << y;
}

}  // namespace
}  // namespace mrgi
