// The animated PNG writer (mrgi/animated_png.h): every chunk's CRC and the APNG sequence are
// right, the still image a plain PNG reader sees is frame 0, and each frame, cut out of the clip
// into a PNG of its own, decodes to exactly the pixels given.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/animated_png.h"
#include "mrgi/image.h"

namespace mrgi {
namespace {

uint32_t be32(const uint8_t* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }

struct Chunk {
  std::string type;
  std::vector<uint8_t> data;
};

std::vector<Chunk> read_chunks(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), {});
  static const uint8_t sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  EXPECT_GE(b.size(), 8u);
  EXPECT_EQ(std::memcmp(b.data(), sig, 8), 0);
  std::vector<Chunk> out;
  size_t p = 8;
  while (p + 12 <= b.size()) {
    const uint32_t len = be32(&b[p]);
    Chunk c{std::string(reinterpret_cast<const char*>(&b[p + 4]), 4), {}};
    EXPECT_LE(p + 12 + len, b.size());
    c.data.assign(b.begin() + std::ptrdiff_t(p + 8), b.begin() + std::ptrdiff_t(p + 8 + len));
    // zlib's crc32 with a null buffer returns its initial value: no data, no second call.
    uLong crc = crc32(0L, &b[p + 4], 4);
    if (len > 0) crc = crc32(crc, c.data.data(), uInt(len));
    EXPECT_EQ(be32(&b[p + 8 + len]), uint32_t(crc)) << c.type << " chunk's CRC";
    out.push_back(std::move(c));
    p += 12 + len;
  }
  EXPECT_EQ(p, b.size());
  return out;
}

void write_chunk(std::ofstream& f, const char* type, const std::vector<uint8_t>& data) {
  const uint8_t len[4] = {uint8_t(data.size() >> 24), uint8_t(data.size() >> 16), uint8_t(data.size() >> 8),
                          uint8_t(data.size())};
  f.write(reinterpret_cast<const char*>(len), 4);
  f.write(type, 4);
  f.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(type), 4);
  if (!data.empty()) crc = crc32(crc, data.data(), uInt(data.size()));
  const uint8_t c[4] = {uint8_t(crc >> 24), uint8_t(crc >> 16), uint8_t(crc >> 8), uint8_t(crc)};
  f.write(reinterpret_cast<const char*>(c), 4);
}

ImageRGBA8 pattern(int w, int h, int k) {
  ImageRGBA8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = uint8_t(x * 7 + k * 40);
      p[1] = uint8_t(y * 13 + k);
      p[2] = uint8_t((x ^ y) * (k + 1));
      p[3] = 255;
    }
  return img;
}

TEST(AnimatedPng, EveryFrameDecodesToItsPixelsAndThePlainReaderSeesFrameZero) {
  testing::TempDir dir;
  const std::string path = dir.str() + "/clip.png";
  const int w = 37, h = 21;  // odd sizes: no row or filter arithmetic hides behind a power of two
  std::vector<ImageRGBA8> frames = {pattern(w, h, 0), pattern(w, h, 1), pattern(w, h, 2)};
  {
    auto writer = AnimatedPngWriter::create(path, w, h, 25.0);
    ASSERT_TRUE(writer.ok()) << writer.error().message;
    for (const auto& f : frames) ASSERT_TRUE(writer->add(f).ok());
    EXPECT_FALSE(std::filesystem::exists(path)) << "the clip appears only when finished";
    ASSERT_TRUE(writer->finish().ok());
  }
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));

  const std::vector<Chunk> chunks = read_chunks(path);
  ASSERT_GE(chunks.size(), 4u);
  EXPECT_EQ(chunks.front().type, "IHDR");
  EXPECT_EQ(chunks[1].type, "acTL");
  EXPECT_EQ(be32(chunks[1].data.data()), 3u) << "frame count";
  EXPECT_EQ(chunks.back().type, "IEND");
  // fcTL and fdAT share one sequence 0, 1, 2, ...; each fcTL's delay is 1/25 s.
  uint32_t seq = 0;
  std::vector<std::vector<uint8_t>> frame_data;
  for (const Chunk& c : chunks) {
    if (c.type == "fcTL") {
      EXPECT_EQ(be32(c.data.data()), seq++);
      EXPECT_EQ(be32(&c.data[4]), uint32_t(w));
      EXPECT_EQ(be32(&c.data[8]), uint32_t(h));
      const double delay = double(c.data[20] << 8 | c.data[21]) / double(c.data[22] << 8 | c.data[23]);
      EXPECT_NEAR(delay, 1.0 / 25.0, 1e-9);
    } else if (c.type == "fdAT") {
      EXPECT_EQ(be32(c.data.data()), seq++);
      frame_data.emplace_back(c.data.begin() + 4, c.data.end());
    } else if (c.type == "IDAT") {
      frame_data.push_back(c.data);
    }
  }
  ASSERT_EQ(frame_data.size(), 3u);

  auto still = load_png_rgb8(path);
  ASSERT_TRUE(still.ok()) << still.error().message;
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string single = dir.str() + "/frame" + std::to_string(f) + ".png";
    {
      std::ofstream out(single, std::ios::binary);
      static const char sig[8] = {char(137), 80, 78, 71, 13, 10, 26, 10};
      out.write(sig, 8);
      write_chunk(out, "IHDR", chunks.front().data);
      write_chunk(out, "IDAT", frame_data[f]);
      write_chunk(out, "IEND", {});
    }
    auto img = load_png_rgb8(single);
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->width, w);
    ASSERT_EQ(img->height, h);
    int wrong = 0, wrong_still = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          wrong += img->at(x, y)[c] != frames[f].at(x, y)[c];
          if (f == 0) wrong_still += still->at(x, y)[c] != frames[0].at(x, y)[c];
        }
    EXPECT_EQ(wrong, 0) << "frame " << f;
    EXPECT_EQ(wrong_still, 0);
  }
}

TEST(AnimatedPng, RefusesWhatItCannotWriteAndLeavesNothingBehind) {
  testing::TempDir dir;
  const std::string path = dir.str() + "/clip.png";
  EXPECT_EQ(AnimatedPngWriter::create(path, 0, 10, 30.0).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ(AnimatedPngWriter::create(path, 10, 10, 0.0).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ(AnimatedPngWriter::create(dir.str() + "/no/such/folder/clip.png", 10, 10, 30.0).error().kind,
            ErrorKind::BadInput);
  {
    auto writer = AnimatedPngWriter::create(path, 8, 8, 30.0);
    ASSERT_TRUE(writer.ok());
    EXPECT_EQ(writer->add(ImageRGBA8(9, 8)).error().kind, ErrorKind::BadUsage);
    EXPECT_EQ(writer->finish().error().kind, ErrorKind::BadUsage) << "no frame";
  }
  {
    auto writer = AnimatedPngWriter::create(path, 8, 8, 30.0);
    ASSERT_TRUE(writer->add(ImageRGBA8(8, 8)).ok());
  }  // abandoned without finish()
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
}

}  // namespace
}  // namespace mrgi
