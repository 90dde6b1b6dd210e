// Delta-stored references (*.delta.png): codec, writer, reader rules, in-place conversion, export.
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "capture/capture_fixture.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_references.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;
using testing::CaptureFixture;
using testing::kH;
using testing::kW;
using testing::TempDir;
using testing::write_text;

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A reference that equals the colour frame except in a block, with values on both sides of the
// colour's so the delta wraps around 0 and 255.
ImageRGB8 reference_for(const ImageRGB8& color, int seed) {
  ImageRGB8 ref = color;
  for (int y = 1; y < 4; ++y)
    for (int x = 2; x < 6; ++x)
      for (int c = 0; c < 3; ++c) ref.at(x, y)[c] = uint8_t((x * 53 + y * 91 + c * 17 + seed * 7) % 256);
  return ref;
}

InputFrame frame(int i) {
  InputFrame f;
  f.index = i;
  f.timestamp = f.depth_timestamp = 0.25 + 1.0 / 30.0 * i;  // not exactly representable
  f.color = testing::test_color(kW, kH, i);
  f.depth = testing::test_depth(kW, kH, i);
  return f;
}

CaptureInfo info() {
  CaptureInfo c;
  c.color = c.depth = Intrinsics{kW, kH, 10, 10, 4, 3};
  return c;
}

void write_capture(const std::string& folder, ReferenceStorage storage, int frames = 3) {
  auto w = CaptureWriter::create(folder, info(), std::nullopt, storage);
  ASSERT_TRUE(w.ok()) << w.error().message;
  w->set_png_effort(PngEffort::Small);  // what the conversion writes (and synth)
  for (int i = 0; i < frames; ++i) {
    const InputFrame f = frame(i);
    const ImageRGB8 ref = reference_for(f.color, i);
    const ImageU8 mask(kW, kH, uint8_t(i * 40));
    ASSERT_TRUE(w->add_frame(f, &ref, &mask).ok());
  }
  ASSERT_TRUE(w->finish().ok());
}

TEST(ReferenceDelta, CodecIsLosslessAcrossWrapAround) {
  const ImageRGB8 color = testing::test_color(kW, kH, 3);
  const ImageRGB8 ref = reference_for(color, 5);
  auto delta = encode_reference_delta(ref, color);
  ASSERT_TRUE(delta.ok());
  size_t zero = 0, wrapped = 0;
  for (size_t i = 0; i < ref.data.size(); ++i) {
    zero += delta->data[i] == 0;
    wrapped += ref.data[i] < color.data[i];
  }
  EXPECT_GE(zero, ref.data.size() - 36);  // every value outside the 4x3 block is 0
  EXPECT_LT(zero, ref.data.size() - 30);  // and most inside it are not
  EXPECT_GT(wrapped, 0u);
  auto back = decode_reference_delta(*delta, color);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->data, ref.data);
  EXPECT_ERROR(encode_reference_delta(ref, ImageRGB8(kW + 1, kH)), BadUsage, "same size");
  EXPECT_ERROR(decode_reference_delta(*delta, ImageRGB8(kW, kH - 1)), BadUsage, "same size");
  EXPECT_TRUE(is_delta_reference_path("a/reference/000001.delta.png"));
  EXPECT_FALSE(is_delta_reference_path("a/reference/000001.png"));
  EXPECT_FALSE(is_delta_reference_path("a.delta.png/000001.png"));
}

TEST(ReferenceDelta, WriterStoresDeltaAndReaderReconstructsExactly) {
  TempDir dir;
  const std::string folder = dir.file("cap");
  write_capture(folder, ReferenceStorage::Delta);
  EXPECT_TRUE(fs::exists(folder + "/reference/000001.delta.png"));
  EXPECT_FALSE(fs::exists(folder + "/reference/000001.png"));
  EXPECT_NE(read_all(folder + "/reference.txt").find(" reference/000001.delta.png reference/000001_mask.png\n"),
            std::string::npos);
  // The stored file is (reference - colour) mod 256.
  auto stored = load_png_rgb8(folder + "/reference/000001.delta.png");
  ASSERT_TRUE(stored.ok());
  const InputFrame f1 = frame(1);
  const ImageRGB8 ref1 = reference_for(f1.color, 1);
  for (size_t i = 0; i < ref1.data.size(); ++i) ASSERT_EQ(uint8_t(f1.color.data[i] + stored->data[i]), ref1.data[i]) << i;

  auto reader = CaptureReader::open(folder);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  for (int i = 0; i < 3; ++i) {
    auto r = reader->read_reference(size_t(i));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->data, reference_for(frame(i).color, i).data) << "frame " << i;
    EXPECT_EQ(reader->entry(size_t(i)).reference_line, i + 3);  // after the two comment lines
  }
}

TEST(ReferenceDelta, PlainAndDeltaCapturesDifferOnlyInTheReferenceFiles) {
  TempDir dir;
  write_capture(dir.file("plain"), ReferenceStorage::Plain);
  write_capture(dir.file("delta"), ReferenceStorage::Delta);
  auto plain = CaptureReader::open(dir.file("plain"));
  auto delta = CaptureReader::open(dir.file("delta"));
  ASSERT_TRUE(plain.ok() && delta.ok());
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(plain->read_reference(i)->data, delta->read_reference(i)->data);
  EXPECT_EQ(read_all(dir.file("plain/rgb/000002.png")), read_all(dir.file("delta/rgb/000002.png")));
}

// The rules for a .delta.png, each refused with reference.txt's line.
TEST(ReferenceDeltaRefuses, NoColourFrameOfExactlyItsTimestamp) {
  CaptureFixture f(2);
  ASSERT_TRUE(write_png(f.file("reference/1.delta.png"), ImageRGB8(kW, kH, 0)).ok());
  // 1.105 is within 0.02 s of frame 1 (1.1), which is enough for a plain reference, not a delta.
  write_text(f.file("reference.txt"), "# refs\n1.105 reference/1.delta.png\n");
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "reference.txt:2:", "delta reference",
               "exactly timestamp 1.105", "nearest is 1.1");
  ASSERT_TRUE(write_png(f.file("reference/1.png"), ImageRGB8(kW, kH, 0)).ok());
  write_text(f.file("reference.txt"), "# refs\n1.105 reference/1.png\n");
  EXPECT_TRUE(CaptureReader::open(f.folder()).ok());
}

TEST(ReferenceDeltaRefuses, SizeDifferentFromItsColourFrame) {
  CaptureFixture f(2);
  ASSERT_TRUE(write_png(f.file("reference/0.png"), ImageRGB8(kW, kH, 0)).ok());
  ASSERT_TRUE(write_png(f.file("reference/1.delta.png"), ImageRGB8(kW - 2, kH, 0)).ok());
  write_text(f.file("reference.txt"),
             "1.000000 reference/0.png\n" + CaptureFixture::time(1) + " reference/1.delta.png\n");
  auto reader = CaptureReader::open(f.folder());  // open() reads the first reference only
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_ERROR(reader->read_reference(1), BadInput, "reference.txt:2:", "delta reference", "is 6x6",
               "colour frame", "is 8x6", "size of the colour frame");
  // Also when the colour frame is the one whose size is wrong (the delta matches the intrinsics).
  ASSERT_TRUE(write_png(f.file("reference/1.delta.png"), ImageRGB8(kW, kH, 0)).ok());
  ASSERT_TRUE(write_png(f.file("rgb/1.png"), ImageRGB8(kW, kH + 2, 0)).ok());
  EXPECT_ERROR(reader->read_reference(1), BadInput, "reference.txt:2:", "is 8x6", "is 8x8");
}

TEST(ReferenceDeltaRefuses, NotEightBitRgb) {
  CaptureFixture f(1);
  write_text(f.file("reference.txt"), "# refs\n# more\n1.000000 reference/0.delta.png\n");
  ASSERT_TRUE(write_png(f.file("reference/0.delta.png"), ImageU8(kW, kH, 3)).ok());
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "reference.txt:3:", "delta reference",
               "PNG is 8-bit grey", "8-bit RGB");
  ASSERT_TRUE(write_png(f.file("reference/0.delta.png"), ImageRGBA8(kW, kH, 3)).ok());
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "reference.txt:3:", "PNG is 8-bit RGBA", "8-bit RGB");
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = kW;
  image.height = kH;
  image.format = PNG_FORMAT_LINEAR_RGB;
  std::vector<uint16_t> pixels(size_t(kW) * kH * 3, 3);
  ASSERT_TRUE(png_image_write_to_file(&image, f.file("reference/0.delta.png").c_str(), 0, pixels.data(), 0, nullptr));
  EXPECT_ERROR(CaptureReader::open(f.folder()), BadInput, "reference.txt:3:", "PNG is 16-bit RGB", "8-bit RGB");
}

TEST(ReferenceDeltaRefuses, ColourFrameGoneAfterOpen) {
  TempDir dir;
  const std::string folder = dir.file("cap");
  write_capture(folder, ReferenceStorage::Delta);
  auto reader = CaptureReader::open(folder);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  fs::remove(folder + "/rgb/000002.png");
  EXPECT_ERROR(reader->read_reference(2), NotFound, "reference.txt:5:", "its colour frame", "000002.png");
}

TEST(ReferenceConversion, PlainToDeltaGivesTheWritersBytesAndBack) {
  TempDir dir;
  write_capture(dir.file("plain"), ReferenceStorage::Plain);
  write_capture(dir.file("delta"), ReferenceStorage::Delta);
  write_capture(dir.file("conv"), ReferenceStorage::Plain);

  auto to_delta = convert_capture_references(dir.file("conv"), ReferenceStorage::Delta);
  ASSERT_TRUE(to_delta.ok()) << to_delta.error().message;
  EXPECT_EQ(to_delta->converted, 3u);
  EXPECT_EQ(to_delta->unchanged, 0u);
  // Exactly the files a Delta writer makes: same names, same bytes, old plain files gone.
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.file("delta"))) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir.file("delta"));
    EXPECT_EQ(read_all(e.path()), read_all(dir.file("conv") / rel)) << rel;
    ++files;
  }
  size_t conv_files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.file("conv"))) conv_files += e.is_regular_file();
  EXPECT_EQ(conv_files, files);

  auto again = convert_capture_references(dir.file("conv"), ReferenceStorage::Delta);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->converted, 0u);
  EXPECT_EQ(again->unchanged, 3u);

  auto to_plain = convert_capture_references(dir.file("conv"), ReferenceStorage::Plain);
  ASSERT_TRUE(to_plain.ok()) << to_plain.error().message;
  EXPECT_EQ(to_plain->converted, 3u);
  for (const char* rel : {"reference.txt", "reference/000000.png", "reference/000002.png", "reference/000001_mask.png"})
    EXPECT_EQ(read_all(dir.file("plain") + "/" + rel), read_all(dir.file("conv") + "/" + rel)) << rel;
  EXPECT_FALSE(fs::exists(dir.file("conv/reference/000000.delta.png")));
}

TEST(ReferenceConversion, RefusesWithoutTouchingTheCapture) {
  TempDir dir;
  const std::string folder = dir.file("cap");
  write_capture(folder, ReferenceStorage::Plain);
  const std::string list_before = read_all(folder + "/reference.txt");
  // A stray file where the delta would go: nothing is overwritten, nothing changes.
  write_text(folder + "/reference/000001.delta.png", "stray");
  EXPECT_ERROR(convert_capture_references(folder, ReferenceStorage::Delta), BadUsage, "reference.txt:4:",
               "000001.delta.png", "already exists");
  EXPECT_EQ(read_all(folder + "/reference.txt"), list_before);
  EXPECT_TRUE(fs::exists(folder + "/reference/000000.png"));
  EXPECT_TRUE(CaptureReader::open(folder).ok());
  // A capture without references, and a broken one, are refused as the reader refuses them.
  CaptureFixture f(1);
  EXPECT_ERROR(convert_capture_references(f.folder(), ReferenceStorage::Delta), NotFound, "reference.txt",
               "no references");
  EXPECT_ERROR(convert_capture_references(dir.file("nothing"), ReferenceStorage::Delta), NotFound,
               "does not exist");
}

TEST(ReferenceExport, WritesPlainPngsOfTheReconstructedReferences) {
  TempDir dir;
  write_capture(dir.file("cap"), ReferenceStorage::Delta);
  auto reader = CaptureReader::open(dir.file("cap"));
  ASSERT_TRUE(reader.ok());
  auto n = export_references(*reader, dir.file("out"));
  ASSERT_TRUE(n.ok()) << n.error().message;
  EXPECT_EQ(*n, 3u);
  for (int i = 0; i < 3; ++i) {
    auto png = load_png_rgb8(dir.file("out/00000" + std::to_string(i) + ".png"));
    ASSERT_TRUE(png.ok()) << png.error().message;
    EXPECT_EQ(png->data, reference_for(frame(i).color, i).data);
  }
  EXPECT_ERROR(export_references(*reader, dir.file("out")), BadUsage, "out", "not an empty folder");
  CaptureFixture f(1);
  auto plain = CaptureReader::open(f.folder());
  ASSERT_TRUE(plain.ok());
  EXPECT_ERROR(export_references(*plain, dir.file("out2")), NotFound, "no reference frames");
}

}  // namespace
}  // namespace mrgi
