// CaptureWriter::resume: a write cut off after some frames goes on to the same files as one
// uninterrupted write; what cannot be resumed is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "capture/capture_fixture.h"
#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;
using testing::kH;
using testing::kW;
using testing::TempDir;

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

CaptureInfo info() {
  CaptureInfo c;
  c.color = c.depth = Intrinsics{kW, kH, 10, 10, 4, 3};
  return c;
}

InputFrame frame(int i) {
  InputFrame f;
  f.index = i;
  f.timestamp = f.depth_timestamp = 0.1 + 1.0 / 30.0 * i;
  f.color = testing::test_color(kW, kH, i);
  f.depth = testing::test_depth(kW, kH, i);
  Pose p;
  p.translation = {0.1 * i, 0.2, 0.3};
  f.pose = p;
  if (i % 2 == 0) f.env = ImageRGBF(4, 2, float(i));
  return f;
}

Status add(CaptureWriter& w, int i) {
  const InputFrame f = frame(i);
  const ImageRGB8 ref = testing::test_color(kW, kH, 100 + i);
  const ImageU8 mask(kW, kH, uint8_t(10 * i));
  return w.add_frame(f, &ref, &mask);
}

TEST(CaptureWriterResume, CutOffWriteGoesOnToTheSameFiles) {
  TempDir dir;
  SceneDesc scene;
  testing::write_text(dir.file("obj.glb"), "glb");
  scene.virtual_objects.push_back({dir.file("obj.glb"), Placement{}});
  {
    auto w = CaptureWriter::create(dir.file("whole"), info(), scene, ReferenceStorage::Delta);
    ASSERT_TRUE(w.ok()) << w.error().message;
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(add(*w, i).ok());
    ASSERT_TRUE(w->finish().ok());
  }
  {
    auto w = CaptureWriter::create(dir.file("cut"), info(), scene, ReferenceStorage::Delta);
    ASSERT_TRUE(w.ok());
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(add(*w, i).ok());
  }  // dropped without finish(), as a killed process would leave it
  // Half of frame 2 was written when the process died.
  testing::write_text(dir.file("cut.partial/rgb/000002.png"), "half a PNG");
  EXPECT_FALSE(fs::exists(dir.file("cut")));
  {
    auto w = CaptureWriter::resume(dir.file("cut"), info(), scene, ReferenceStorage::Delta);
    ASSERT_TRUE(w.ok()) << w.error().message;
    EXPECT_EQ(w->frame_count(), 2u);
    // The timestamp rule holds across the resume: frame 1 again is refused.
    EXPECT_ERROR(add(*w, 1), BadUsage, "does not increase");
    for (int i = 2; i < 4; ++i) ASSERT_TRUE(add(*w, i).ok());
    ASSERT_TRUE(w->finish().ok());
  }
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.file("whole"))) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir.file("whole"));
    EXPECT_EQ(read_all(e.path()), read_all(dir.file("cut") / rel)) << rel;
    ++files;
  }
  size_t cut_files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.file("cut"))) cut_files += e.is_regular_file();
  EXPECT_EQ(cut_files, files);  // no progress file left behind
  EXPECT_FALSE(fs::exists(dir.file("whole/writer_progress.json")));
  EXPECT_TRUE(CaptureReader::open(dir.file("cut")).ok());
}

TEST(CaptureWriterResume, Refusals) {
  TempDir dir;
  EXPECT_ERROR(CaptureWriter::resume(dir.file("none"), info(), std::nullopt), NotFound, "none.partial",
               "no interrupted write");
  {
    auto w = CaptureWriter::create(dir.file("cap"), info(), std::nullopt, ReferenceStorage::Plain);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(add(*w, 0).ok());
  }
  EXPECT_ERROR(CaptureWriter::resume(dir.file("cap"), info(), std::nullopt, ReferenceStorage::Delta), BadUsage,
               "writer_progress.json", "plain", "delta");
  testing::write_text(dir.file("cap.partial/writer_progress.json"), "{\"version\": 1}");
  EXPECT_ERROR(CaptureWriter::resume(dir.file("cap"), info(), std::nullopt), BadInput, "writer_progress.json",
               "reference_storage");
  fs::remove(dir.file("cap.partial/writer_progress.json"));
  EXPECT_ERROR(CaptureWriter::resume(dir.file("cap"), info(), std::nullopt), NotFound, "writer_progress.json",
               "missing");
  // A finished capture is not resumed.
  auto w = CaptureWriter::create(dir.file("done"), info(), std::nullopt);
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(add(*w, 0).ok());
  ASSERT_TRUE(w->finish().ok());
  EXPECT_ERROR(CaptureWriter::resume(dir.file("done"), info(), std::nullopt), BadUsage, "already exists");
}

}  // namespace
}  // namespace mrgi
