// mrgi record: the Kinect .oni recorded to capture format v1 and read back with CaptureReader
// must give the same frames bit for bit (colour, depth, timestamps) and the same camera info.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "mrgi/platform/capture.h"
#include "mrgi/platform/devices.h"
#include "test_support.h"

namespace mrgi {
namespace {

const std::string kOni = test::shared_data("openni/kinect-12frames.oni");

std::vector<InputFrame> read_all(InputSource& s) {
  std::vector<InputFrame> out;
  for (;;) {
    auto f = s.next(std::chrono::milliseconds(3000));
    if (!f.ok()) {
      EXPECT_EQ(f.error().kind, ErrorKind::EndOfStream) << f.error().message;
      return out;
    }
    out.push_back(std::move(f.value()));
  }
}

void expect_capture_equals_oni(const std::string& folder) {
  auto reader = CaptureReader::open(folder);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  auto oni = open_openni_source(kOni);
  ASSERT_TRUE(oni.ok()) << oni.error().message;
  const auto expected = read_all(**oni);
  ASSERT_EQ(expected.size(), 12u);
  ASSERT_EQ(reader->frame_count(), expected.size());
  const CaptureInfo& a = reader->info();
  const CaptureInfo& b = (*oni)->info();
  EXPECT_EQ(a.depth_scale, b.depth_scale);
  EXPECT_EQ(a.color.width, b.color.width);
  EXPECT_DOUBLE_EQ(a.color.fx, b.color.fx);
  EXPECT_DOUBLE_EQ(a.color.cy, b.color.cy);
  EXPECT_DOUBLE_EQ(a.depth.fy, b.depth.fy);
  for (size_t i = 0; i < expected.size(); ++i) {
    auto f = reader->read_frame(i);
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ(f->timestamp, expected[i].timestamp) << "frame " << i;
    EXPECT_EQ(f->depth_timestamp, expected[i].depth_timestamp) << "frame " << i;
    EXPECT_TRUE(f->color.data == expected[i].color.data) << "colour of frame " << i << " differs";
    EXPECT_TRUE(f->depth.data == expected[i].depth.data) << "depth of frame " << i << " differs";
    EXPECT_FALSE(f->pose.has_value());
  }
}

TEST(Record, OniToCaptureRoundTripsBitExact) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(120), "recording the .oni", [] {
    test::TempDir dir("record");
    const std::string out = dir.file("kinect");
    auto src = open_source("openni:" + kOni, SourceOptions{});
    ASSERT_TRUE(src.ok()) << src.error().message;
    auto n = record_to_capture(**src, out, RecordSettings{});
    ASSERT_TRUE(n.ok()) << n.error().message;
    EXPECT_EQ(*n, 12u);
    src.value().reset();  // one open playback per file and process
    expect_capture_equals_oni(out);
    // A capture replays through open_source as a folder, frame for frame.
    auto replay = open_source(out, SourceOptions{});
    ASSERT_TRUE(replay.ok()) << replay.error().message;
    EXPECT_EQ(read_all(**replay).size(), 12u);
  });
}

TEST(Record, FailureMidStreamLeavesNothing) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::run_with_deadline(std::chrono::seconds(60), "recording a broken .oni", [] {
    test::TempDir dir("record-bad");
    // Depth frame 5's payload overwritten: playback either stalls (BadInput) or ends early;
    // either way a capture is all or nothing.
    std::ifstream in(kOni, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    std::fill(bytes.begin() + 797600, bytes.begin() + 902000, char(0x5A));
    const std::string broken = dir.file("broken.oni");
    std::ofstream(broken, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    auto src = open_source("openni:" + broken, SourceOptions{});
    ASSERT_TRUE(src.ok()) << src.error().message;
    RecordSettings s;
    s.timeout = std::chrono::milliseconds(2500);
    const std::string out = dir.file("cap");
    auto n = record_to_capture(**src, out, s);
    if (!n.ok()) {
      EXPECT_NE(n.error().message.find("nothing written"), std::string::npos) << n.error().message;
      EXPECT_FALSE(std::filesystem::exists(out));
      EXPECT_FALSE(std::filesystem::exists(out + ".partial"));
    } else {
      EXPECT_LE(*n, 12u);
      EXPECT_TRUE(CaptureReader::open(out).ok());
    }
  });
}

TEST(Record, ToolRecordsTheOni) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  if (!std::filesystem::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  test::TempDir dir("record-tool");
  const std::string out = dir.file("cap");
  const std::string cmd = std::string("timeout 120 ") + MRGI_TOOL + " record openni:" + kOni + " --out " + out + " -q > " +
                          dir.file("stdout.txt") + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  expect_capture_equals_oni(out);
  // Recording over an existing capture is refused (exit 2, bad usage), and leaves it intact.
  const std::string again = std::string("timeout 60 ") + MRGI_TOOL + " record openni:" + kOni + " --out " + out + " -q > /dev/null 2>&1";
  const int rc = std::system(again.c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  expect_capture_equals_oni(out);
}

}  // namespace
}  // namespace mrgi
