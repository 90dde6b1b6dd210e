// OpenNI2 adapter on the real Kinect v1 recording (../shared/data/openni/kinect-12frames.oni:
// 12 depth + 12 colour frames, 640x480, depth in mm), plus truncated and corrupt copies.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

#include "mrgi/platform/openni.h"
#include "openni/oni_file_inspector.h"
#include "test_support.h"

namespace mrgi {
namespace {

const std::string kOni = test::shared_data("openni/kinect-12frames.oni");
constexpr auto kWait = std::chrono::milliseconds(3000);

std::vector<char> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}
void write_all(const std::string& path, const char* data, size_t n) {
  std::ofstream out(path, std::ios::binary);
  out.write(data, std::streamsize(n));
}

TEST(OniFileInspector, RealRecordingStructure) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  auto s = oni::inspect_oni_file(kOni);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->nodes.at(s->depth_node).name, "Depth1");
  EXPECT_EQ(s->nodes.at(s->image_node).name, "Image1");
  EXPECT_EQ(s->nodes.at(s->depth_node).data_records, 12);
  EXPECT_EQ(s->nodes.at(s->image_node).data_records, 12);
  EXPECT_EQ(s->int_property(s->depth_node, "AlternativeViewPoint", 7), 1u);
  EXPECT_EQ(s->int_property(s->image_node, "AlternativeViewPoint", 7), 0u);
  EXPECT_EQ(s->max_timestamp_us, 378742u);
}

TEST(OpenNISource, ReadsEveryFrameOfTheKinectRecording) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(60), "reading kinect-12frames.oni", [] {
    auto src = open_openni_source(kOni);
    ASSERT_TRUE(src.ok()) << src.error().message;
    InputSource& s = **src;
    const CaptureInfo& info = s.info();
    EXPECT_EQ(info.depth_scale, 1000.0);
    EXPECT_EQ(info.color.width, 640);
    EXPECT_EQ(info.color.height, 480);
    // Depth stream FOV recorded in the file: 1.014469 x 0.789809 rad.
    EXPECT_NEAR(info.depth.fx, 320.0 / std::tan(1.014469 / 2), 0.05);
    EXPECT_NEAR(info.depth.fy, 240.0 / std::tan(0.789809 / 2), 0.05);
    EXPECT_NEAR(info.color.fx, info.depth.fx, 1e-9);  // registered: one geometry
    EXPECT_NEAR(info.color.cx, 319.5, 1e-9);
    const OpenNIStreamReport* r = openni_report(s);
    ASSERT_NE(r, nullptr);
    EXPECT_TRUE(r->is_file);
    EXPECT_TRUE(r->registered) << r->registration_source;
    EXPECT_EQ(r->depth_frames_in_file, 12);
    EXPECT_EQ(r->color_frames_in_file, 12);
    EXPECT_TRUE(r->mirrored);

    double last_ts = -1, last_depth_ts = -1;
    int frames = 0;
    for (;;) {
      auto f = s.next(kWait);
      if (!f.ok()) {
        EXPECT_EQ(f.error().kind, ErrorKind::EndOfStream) << f.error().message;
        break;
      }
      ASSERT_LT(frames, 12) << "more frames than the file holds";
      EXPECT_EQ(f->index, frames);
      EXPECT_EQ(f->color.width, 640);
      EXPECT_EQ(f->color.height, 480);
      EXPECT_EQ(f->depth.width, 640);
      EXPECT_EQ(f->depth.height, 480);
      EXPECT_GT(f->timestamp, last_ts);
      EXPECT_GT(f->depth_timestamp, last_depth_ts);
      EXPECT_LT(std::abs(f->depth_timestamp - f->timestamp), 0.02);  // 11.7 ms apart in this file
      last_ts = f->timestamp;
      last_depth_ts = f->depth_timestamp;
      // A real indoor Kinect frame: most pixels measured, median between 0.5 m and 8 m.
      std::vector<uint16_t> valid;
      for (uint16_t d : f->depth.data)
        if (d) valid.push_back(d);
      EXPECT_GT(valid.size(), f->depth.pixel_count() / 2);
      std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
      EXPECT_GT(valid[valid.size() / 2], 500);
      EXPECT_LT(valid[valid.size() / 2], 8000);
      // Colour decoded from the file's JPEG: not flat.
      auto [mn, mx] = std::minmax_element(f->color.data.begin(), f->color.data.end());
      EXPECT_GT(int(*mx) - int(*mn), 100);
      ++frames;
    }
    EXPECT_EQ(frames, 12);
    EXPECT_NEAR(last_ts, 0.366719, 1e-6);
    EXPECT_NEAR(last_depth_ts, 0.378742, 1e-6);
    auto again = s.next(kWait);  // stays ended
    ASSERT_FALSE(again.ok());
    EXPECT_EQ(again.error().kind, ErrorKind::EndOfStream);
  });
}

TEST(OpenNISource, TruncatedFileIsANamedError) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(30), "opening a truncated .oni", [] {
    test::TempDir dir("oni-trunc");
    const auto bytes = read_all(kOni);
    ASSERT_EQ(bytes.size(), 2124474u);
    for (size_t keep : {size_t(10), size_t(30000), bytes.size() * 6 / 10, bytes.size() - 1}) {
      const std::string path = dir.file("cut" + std::to_string(keep) + ".oni");
      write_all(path, bytes.data(), keep);
      auto src = open_openni_source(path);
      ASSERT_FALSE(src.ok()) << "kept " << keep;
      EXPECT_EQ(src.error().kind, ErrorKind::BadInput);
      EXPECT_NE(src.error().message.find("truncated"), std::string::npos) << src.error().message;
      EXPECT_NE(src.error().message.find(path), std::string::npos) << src.error().message;
    }
  });
}

TEST(OpenNISource, CorruptFilesAreNamedErrorsNotHangs) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(60), "reading corrupt .oni files", [] {
    test::TempDir dir("oni-corrupt");
    auto bytes = read_all(kOni);
    // Not an OpenNI file at all.
    std::vector<char> junk(4096);
    for (size_t i = 0; i < junk.size(); ++i) junk[i] = char((i * 2654435761u) >> 13);
    write_all(dir.file("junk.oni"), junk.data(), junk.size());
    auto a = open_openni_source(dir.file("junk.oni"));
    ASSERT_FALSE(a.ok());
    EXPECT_EQ(a.error().kind, ErrorKind::BadInput);
    EXPECT_NE(a.error().message.find("NI10"), std::string::npos) << a.error().message;

    // A record header overwritten in the middle (bytes 554000..554200 hold the header of colour
    // frame 4's record at 554081).
    auto broken = bytes;
    std::fill(broken.begin() + 554000, broken.begin() + 554200, char(0xA5));
    write_all(dir.file("header.oni"), broken.data(), broken.size());
    auto b = open_openni_source(dir.file("header.oni"));
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.error().kind, ErrorKind::BadInput);
    EXPECT_NE(b.error().message.find("byte 554081"), std::string::npos) << b.error().message;

    // Frame payloads overwritten (depth frame 5's compressed data, 797490..902777) with the
    // structure intact: the reader must end with frames or a named error, bounded in time.
    auto payload = bytes;
    std::fill(payload.begin() + 797600, payload.begin() + 902000, char(0x5A));
    write_all(dir.file("payload.oni"), payload.data(), payload.size());
    auto c = open_openni_source(dir.file("payload.oni"));
    ASSERT_TRUE(c.ok()) << c.error().message;
    int frames = 0;
    for (;;) {
      auto f = (*c)->next(std::chrono::milliseconds(2500));
      if (!f.ok()) {
        EXPECT_TRUE(f.error().kind == ErrorKind::EndOfStream || f.error().kind == ErrorKind::BadInput)
            << to_string(f.error().kind) << ": " << f.error().message;
        break;
      }
      ASSERT_LE(++frames, 12);
    }
  });
}

// One changed byte in a property name (the second node's
// "xnSupportedMapOutputModesCount", so the driver never reads the count it then uses) passes the
// record-structure check and segfaulted inside OpenNI2's Device::open. The probe process takes
// the crash: a named BadInput, this process unharmed, nothing opened.
TEST(OpenNISource, AFileThatCrashesTheDriverIsRefusedNotFatal) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(90), "probing a driver-crashing .oni", [] {
    test::TempDir dir("oni-crash");
    auto bytes = read_all(kOni);
    const std::string name = "xnSupportedMapOutputModesCount";
    const std::string text(bytes.begin(), bytes.end());
    const size_t first = text.find(name);
    ASSERT_NE(first, std::string::npos);
    const size_t second = text.find(name, first + 1);
    ASSERT_NE(second, std::string::npos);
    bytes[second + 22] = char(0xFA);
    write_all(dir.file("renamed.oni"), bytes.data(), bytes.size());
    ASSERT_TRUE(oni::inspect_oni_file(dir.file("renamed.oni")).ok()) << "the structure check must pass for this case";
    auto src = open_openni_source(dir.file("renamed.oni"));
    ASSERT_FALSE(src.ok());
    EXPECT_EQ(src.error().kind, ErrorKind::BadInput);
    EXPECT_NE(src.error().message.find("crashed"), std::string::npos) << src.error().message;
    EXPECT_NE(src.error().message.find("renamed.oni"), std::string::npos) << src.error().message;
    // The same process still opens the intact recording afterwards.
    auto good = open_openni_source(kOni);
    EXPECT_TRUE(good.ok()) << good.error().message;
  });
}

// A folder named like a recording (reading it as one would throw std::bad_alloc) and a FIFO
// (opening it would block) are refused as BadInput ("not a regular file").
TEST(OpenNISource, AFolderOrFifoNamedOniIsABadInputNotACrash) {
  test::TempDir dir("oni-not-a-file");
  std::filesystem::create_directories(dir.file("folder.oni"));
  auto a = open_openni_source(dir.file("folder.oni"));
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().kind, ErrorKind::BadInput);
  EXPECT_NE(a.error().message.find("not a regular file"), std::string::npos) << a.error().message;
  ASSERT_EQ(mkfifo(dir.file("pipe.oni").c_str(), 0600), 0);
  auto b = open_openni_source(dir.file("pipe.oni"));
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().kind, ErrorKind::BadInput);
}

TEST(OpenNISource, SecondOpenOfTheSameFileIsRefusedUntilTheFirstCloses) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  auto a = open_openni_source(kOni);
  ASSERT_TRUE(a.ok()) << a.error().message;
  auto b = open_openni_source(kOni);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().kind, ErrorKind::Device);
  EXPECT_NE(b.error().message.find("already open"), std::string::npos) << b.error().message;
  a.value().reset();
  auto c = open_openni_source(kOni);
  ASSERT_TRUE(c.ok()) << c.error().message;
  auto f = (*c)->next(kWait);
  ASSERT_TRUE(f.ok()) << f.error().message;
  EXPECT_EQ(f->index, 0);
}

TEST(OpenNISource, MissingFileAndNoDeviceAreNotFound) {
  auto a = open_openni_source("/nonexistent/x.oni");
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().kind, ErrorKind::NotFound);
  // No sensor is attached to test machines: the first-device form must say NotFound, not hang.
  auto devices = list_openni_devices();
  ASSERT_TRUE(devices.ok()) << devices.error().message;
  if (devices->empty()) {
    auto b = open_openni_source("");
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.error().kind, ErrorKind::NotFound) << b.error().message;
  }
}

}  // namespace
}  // namespace mrgi
