// The tool's device-facing commands end to end: `mrgi devices` on a machine without devices,
// `mrgi live` on the Kinect recording (default object), and `mrgi record` + `mrgi replay`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mrgi/image.h"
#include "test_support.h"

namespace mrgi {
namespace {

const std::string kOni = test::shared_data("openni/kinect-12frames.oni");

int run(const std::string& cmd) { return test::run_command(cmd); }
std::string slurp(const std::string& path) { return test::read_text(path); }

size_t count_files(const std::string& dir) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) n += e.is_regular_file();
  return n;
}

class ToolCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  }
};

TEST_F(ToolCommands, DevicesReportsEveryAdapterAndExitsZero) {
  test::TempDir dir("devices");
  ASSERT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " devices --json > " + dir.file("out.json") + " 2> " + dir.file("err.txt")), 0)
      << slurp(dir.file("err.txt"));
  const auto j = nlohmann::json::parse(slurp(dir.file("out.json")));
  for (const char* k : {"openni", "v4l2", "libcamera", "usb"}) {
    ASSERT_TRUE(j.contains(k)) << k;
    EXPECT_FALSE(j[k]["status"].get<std::string>().empty()) << k;
  }
  ASSERT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " devices > " + dir.file("out.txt") + " 2>&1"), 0);
  const std::string text = slurp(dir.file("out.txt"));
  for (const char* k : {"OpenNI2:", "V4L2:", "libcamera:", "USB sensors:"}) EXPECT_NE(text.find(k), std::string::npos) << text;
  // Which adapters this build has (the tested build has all five).
  ASSERT_TRUE(j.contains("adapters"));
  EXPECT_EQ(j["adapters"].size(), 5u);
  for (const auto& a : j["adapters"]) EXPECT_TRUE(a["built"].get<bool>()) << a.dump();
  EXPECT_NE(text.find("adapters in this build: openni2 v4l2 libcamera usb apriltag"), std::string::npos) << text;
}

// replay's side_by_side.png: four labelled panels (camera | mrgi | reference | difference x 4)
// on a capture with references, each panel the output's size under a label bar.
TEST_F(ToolCommands, ReplaySideBySideHasFourLabelledPanels) {
  test::TempDir dir("side-by-side");
  const std::string out = dir.file("out");
  ASSERT_EQ(run(std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                "/data/sample --technique baseline --level last --frames 1 --out " + out + " -q > /dev/null 2> " +
                dir.file("err.txt")),
            0)
      << slurp(dir.file("err.txt"));
  auto sbs = load_png_rgb8(out + "/side_by_side.png");
  ASSERT_TRUE(sbs.ok()) << sbs.error().message;
  auto frame = load_png_rgba8(out + "/frames/000000.png");
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_EQ(sbs->width, 4 * frame->width);
  EXPECT_GT(sbs->height, frame->height);  // the label bar
  // The label bar holds light text on a dark ground in each panel.
  for (int p = 0; p < 4; ++p) {
    int light = 0;
    for (int y = 0; y < sbs->height - frame->height; ++y)
      for (int x = p * frame->width; x < p * frame->width + frame->width / 2; ++x) light += sbs->at(x, y)[0] > 200;
    EXPECT_GT(light, 10) << "panel " << p << " has no label";
  }
}

// replay --output: overlay/ holds the passthrough overlay (premultiplied RGBA, mrgi/overlay.h)
// beside frames/, only the overlay when composite is not named, and an unknown image is refused
// with exit 2 before anything runs.
TEST_F(ToolCommands, ReplayOutputWritesTheOverlayItNames) {
  test::TempDir dir("overlay");
  const std::string replay = std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                             "/data/sample --technique baseline --level last --frames 2 -q";
  const std::string both = dir.file("both"), only = dir.file("only");
  ASSERT_EQ(run(replay + " --out " + both + " --output composite,overlay > /dev/null 2> " + dir.file("err.txt")), 0)
      << slurp(dir.file("err.txt"));
  EXPECT_EQ(count_files(both + "/frames"), 2u);
  EXPECT_EQ(count_files(both + "/overlay"), 2u);
  auto overlay = load_png_rgba8(both + "/overlay/000000.png");
  ASSERT_TRUE(overlay.ok()) << overlay.error().message;
  size_t opaque = 0, clear = 0;
  for (size_t p = 0; p < overlay->data.size() / 4; ++p) {
    opaque += overlay->data[4 * p + 3] == 255;
    clear += overlay->data[4 * p + 3] == 0;
  }
  EXPECT_GT(opaque, 1000u) << "the virtual object";
  EXPECT_GT(clear, overlay->data.size() / 8) << "the real pixels it leaves as they are";
  ASSERT_EQ(run(replay + " --out " + only + " --output overlay > /dev/null 2> " + dir.file("err.txt")), 0)
      << slurp(dir.file("err.txt"));
  EXPECT_FALSE(std::filesystem::exists(only + "/frames"));
  EXPECT_EQ(count_files(only + "/overlay"), 2u);
  EXPECT_EQ(run(replay + " --out " + dir.file("bad") + " --output overlay,mask > /dev/null 2> " + dir.file("err.txt")), 2);
  EXPECT_NE(slurp(dir.file("err.txt")).find("mask not in {composite,overlay}"), std::string::npos) << slurp(dir.file("err.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad")));
}

// replay --video: the composited frames as an animated PNG whose still image is frame 0; names
// it cannot write are refused before anything runs.
TEST_F(ToolCommands, ReplayVideoIsAClipOfTheComposites) {
  test::TempDir dir("video");
  const std::string out = dir.file("out"), clip = dir.file("clip.png");
  const std::string replay = std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                             "/data/sample --technique baseline --level last --frames 3 -q --out " + out;
  ASSERT_EQ(run(replay + " --video " + clip + " > /dev/null 2> " + dir.file("err.txt")), 0) << slurp(dir.file("err.txt"));
  auto still = load_png_rgb8(clip);
  ASSERT_TRUE(still.ok()) << still.error().message;
  auto frame0 = load_png_rgba8(out + "/frames/000000.png");
  ASSERT_TRUE(frame0.ok());
  ASSERT_EQ(still->width, frame0->width);
  int wrong = 0;
  for (int y = 0; y < still->height; ++y)
    for (int x = 0; x < still->width; ++x)
      for (int c = 0; c < 3; ++c) wrong += still->at(x, y)[c] != frame0->at(x, y)[c];
  EXPECT_EQ(wrong, 0);
  const std::string bytes = slurp(clip);
  EXPECT_NE(bytes.find("acTL"), std::string::npos);
  size_t fdat = 0;
  for (size_t p = bytes.find("fdAT"); p != std::string::npos; p = bytes.find("fdAT", p + 4)) ++fdat;
  EXPECT_GE(fdat, 2u) << "frames 1 and 2";

  // Refused with exit 2 and nothing written: an unknown container, a clip inside --out.
  const std::string out2 = dir.file("out2");
  const std::string replay2 = std::string("timeout 60 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                              "/data/sample --frames 1 -q --out " + out2;
  EXPECT_EQ(run(replay2 + " --video " + dir.file("clip.avi") + " > /dev/null 2> " + dir.file("e1.txt")), 2);
  EXPECT_NE(slurp(dir.file("e1.txt")).find(".png or .apng"), std::string::npos) << slurp(dir.file("e1.txt"));
  EXPECT_EQ(run(replay2 + " --video " + out2 + "/clip.png > /dev/null 2> " + dir.file("e2.txt")), 2);
  EXPECT_NE(slurp(dir.file("e2.txt")).find("inside the --out folder"), std::string::npos) << slurp(dir.file("e2.txt"));
  EXPECT_FALSE(std::filesystem::exists(out2));
  if (run("command -v ffmpeg > /dev/null") != 0) {
    EXPECT_EQ(run(replay2 + " --video " + dir.file("clip.mp4") + " > /dev/null 2> " + dir.file("e3.txt")), 2);
    EXPECT_NE(slurp(dir.file("e3.txt")).find("Debian package ffmpeg"), std::string::npos) << slurp(dir.file("e3.txt"));
  } else {  // with ffmpeg present the .mp4 is written
    EXPECT_EQ(run(replay2 + " --video " + dir.file("clip.mp4") + " > /dev/null 2> " + dir.file("e3.txt")), 0)
        << slurp(dir.file("e3.txt"));
    EXPECT_GT(std::filesystem::file_size(dir.file("clip.mp4")), 1000u);
  }
}

// --knob: info prints the ladder with the knob set at every level; replay refuses a knob outside
// its span with exit 2 before opening anything.
// The two I/O modes of replay run the same frames: preloaded (chunks decoded ahead, the runtime
// flushed at each chunk's end, outputs handed back through recycle) writes the same pixels as
// overlapped (stage threads).
TEST_F(ToolCommands, ReplayPreloadedWritesTheFramesOverlappedWrites) {
  test::TempDir dir("io");
  const std::string replay = std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                             "/data/sample --technique baseline --level last --frames 5 -q";
  ASSERT_EQ(run(replay + " --io overlapped --out " + dir.file("a") + " > /dev/null 2> " + dir.file("e1.txt")), 0)
      << slurp(dir.file("e1.txt"));
  // Chunks of 3 (then 2): the first chunk's window holds the 2 frames after its first output;
  // the second chunk's come back together at its flush and hold none.
  ASSERT_EQ(run(replay + " --io preloaded --preload-frames 3 --out " + dir.file("b") + " > " + dir.file("b.json") +
                " 2> " + dir.file("e2.txt")),
            0)
      << slurp(dir.file("e2.txt"));
  // stdout: one line a run, naming the headline figure and where the summary is; the summary
  // says which frame time is the headline and whether the per-pass times can be trusted.
  const std::string line = slurp(dir.file("b.json"));
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << line;
  EXPECT_NE(line.find("sustained "), std::string::npos) << line;
  EXPECT_NE(line.find("RDE all "), std::string::npos) << line;
  EXPECT_NE(line.find("/b/summary.json"), std::string::npos) << line;
  const auto b = nlohmann::json::parse(slurp(dir.file("b") + "/summary.json"));
  EXPECT_NE(b["achieved"]["is"].get<std::string>().find("decode a chunk of frames"), std::string::npos);
  ASSERT_TRUE(b["sustained_ms"].is_number()) << b.dump(1);
  EXPECT_GT(b["sustained_ms"].get<double>(), 0.0);
  EXPECT_GT(b["cpu_ms"].get<double>(), 0.0);
  EXPECT_NE(b["passes_ms_are"].get<std::string>().find("unreliable"), std::string::npos)
      << "lavapipe's GPU timestamps do not time passes: " << b["passes_ms_are"];
  const auto a = nlohmann::json::parse(slurp(dir.file("a") + "/summary.json"));
  EXPECT_TRUE(a["sustained_ms"].is_null()) << "frames beside I/O are not the headline";
  for (int i = 0; i < 5; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/frames/%06d.png", i);
    auto fa = load_png_rgba8(dir.file("a") + name);
    auto fb = load_png_rgba8(dir.file("b") + name);
    ASSERT_TRUE(fa.ok() && fb.ok()) << name;
    EXPECT_TRUE(fa->data == fb->data) << "frame " << i << " differs between the I/O modes";
  }
  // --profile: the passes timed one by one, and said so.
  ASSERT_EQ(run(replay + " --profile --out " + dir.file("c") + " > /dev/null 2> " + dir.file("e3.txt")), 0)
      << slurp(dir.file("e3.txt"));
  const auto c = nlohmann::json::parse(slurp(dir.file("c") + "/summary.json"));
  EXPECT_EQ(c["passes_ms_are"].get<std::string>().rfind("profiled", 0), 0u) << c["passes_ms_are"];
}

// bench's default suite (perf/suite.json) is found from any folder, through the repository the
// tool was built in; a suite found nowhere is refused naming where it was looked for.
TEST_F(ToolCommands, BenchFindsItsSuiteFromAnyFolderOrSaysWhereItLooked) {
  test::TempDir dir("bench-elsewhere");
  const std::string in_dir = "cd " + dir.path.string() + " && LP_NUM_THREADS=2 timeout 300 " + MRGI_TOOL;
  ASSERT_EQ(run(in_dir + " bench --frames 1 -t baseline --levels 3 -s desk_spot -q -o out > /dev/null 2> " +
                dir.file("err.txt")),
            0)
      << slurp(dir.file("err.txt"));
  EXPECT_TRUE(std::filesystem::exists(dir.file("out/bench.json")));
  EXPECT_EQ(run(in_dir + " bench --suite no-such-suite.json -q -o out2 > /dev/null 2> " + dir.file("err2.txt")), 2);
  const std::string err = slurp(dir.file("err2.txt"));
  EXPECT_NE(err.find("looked at " + dir.path.string() + "/no-such-suite.json"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("out2")));
}

// A budget out of range is refused in words (what the number is, its range, an example), exit 2,
// before anything is opened or written.
TEST_F(ToolCommands, FrameBudgetOutOfRangeIsRefusedInWords) {
  test::TempDir dir("budget");
  for (const char* v : {"0", "-5", "abc", "1e7"}) {
    EXPECT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR + "/data/sample --budget-ms " +
                  v + " -q --out " + dir.file("o") + " > /dev/null 2> " + dir.file("err.txt")),
              2)
        << v;
    const std::string err = slurp(dir.file("err.txt"));
    EXPECT_NE(err.find("is not a frame budget"), std::string::npos) << v << ": " << err;
    EXPECT_NE(err.find("33.3 holds 30 fps"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o"))) << v;
  }
}

TEST_F(ToolCommands, KnobsAreSetOneByOneAndRefusedOutsideTheirSpan) {
  test::TempDir dir("knob");
  ASSERT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " info --technique dir --knob vpls=64 --knob bounce_vpls=8 --json > " +
                dir.file("info.json") + " 2> " + dir.file("err.txt")),
            0)
      << slurp(dir.file("err.txt"));
  const auto j = nlohmann::json::parse(slurp(dir.file("info.json")));
  for (const auto& level : j["ladder"]["levels"])
    for (const auto& k : level["knobs"]) {
      if (k["name"] == "vpls") {
        EXPECT_EQ(k["value"].get<double>(), 64.0);
      }
      if (k["name"] == "bounce_vpls") {
        EXPECT_EQ(k["value"].get<double>(), 8.0);
      }
    }
  EXPECT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR + "/data/sample -t dir --knob vpls=4096 -q --out " +
                dir.file("out") + " > /dev/null 2> " + dir.file("err2.txt")),
            2);
  EXPECT_NE(slurp(dir.file("err2.txt")).find("outside 16..256"), std::string::npos) << slurp(dir.file("err2.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
  EXPECT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR + "/data/sample -t dir --knob vpls -q --out " +
                dir.file("out") + " > /dev/null 2> " + dir.file("err3.txt")),
            2);
  EXPECT_NE(slurp(dir.file("err3.txt")).find("NAME=VALUE"), std::string::npos) << slurp(dir.file("err3.txt"));
}

TEST_F(ToolCommands, LiveRendersEveryFrameOfTheOniWithTheDefaultObject) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::TempDir dir("live");
  const std::string out = dir.file("out");
  const std::string cmd = std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " live openni:" + kOni +
                          " --technique baseline --output composite,overlay --out " + out + " -q > " + dir.file("summary.txt") +
                          " 2> " + dir.file("err.txt");
  ASSERT_EQ(run(cmd), 0) << slurp(dir.file("err.txt"));
  EXPECT_EQ(count_files(out + "/frames"), 12u);
  EXPECT_EQ(count_files(out + "/overlay"), 12u) << "--output overlay: the passthrough overlay of every frame";
  const auto summary = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(summary["frames"].get<int>(), 12);
  EXPECT_TRUE(std::filesystem::exists(out + "/stats.json"));
  // Bad source: named error, exit 1, nothing written.
  const std::string bad = dir.file("bad");
  EXPECT_EQ(run(std::string("timeout 60 ") + MRGI_TOOL + " live openni:/nonexistent.oni --out " + bad + " -q > /dev/null 2>&1"), 1);
  EXPECT_FALSE(std::filesystem::exists(bad));
}

// ssrt on a real Kinect recording: every frame has a finite light estimate from the frame it was
// primed on, and stats.json says which frame was run twice for that.
TEST_F(ToolCommands, LiveSsrtOnTheKinectRecordingEstimatesLightFromTheFirstFrame) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::TempDir dir("live-ssrt");
  const std::string out = dir.file("out");
  ASSERT_EQ(run(std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " live openni:" + kOni +
                " --technique ssrt --level fastest --frames 3 --out " + out + " -q > /dev/null 2> " +
                dir.file("err.txt")), 0) << slurp(dir.file("err.txt"));
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  ASSERT_EQ(stats.size(), 3u);
  int primed = 0;
  for (const auto& f : stats) {
    ASSERT_TRUE(f.contains("light")) << f.dump();
    EXPECT_TRUE(f["light"]["valid"].get<bool>()) << "frame " << f["frame"];
    for (const auto& c : f["light"]["sh_radiance"])
      for (const auto& v : c) EXPECT_TRUE(v.is_number()) << "a non-finite coefficient is written as null";
    for (const auto& n : f["notes"]) primed += n.get<std::string>().find("primed") != std::string::npos;
  }
  EXPECT_EQ(primed, 1);
  EXPECT_NE(stats[0]["notes"].dump().find("primed"), std::string::npos) << "frame 0 is the primed one";
}

TEST_F(ToolCommands, RecordedCaptureReplays) {
  MRGI_SKIP_WITHOUT_SHARED(kOni);
  test::TempDir dir("record-replay");
  const std::string cap = dir.file("cap"), out = dir.file("out");
  ASSERT_EQ(run(std::string("timeout 120 ") + MRGI_TOOL + " record openni:" + kOni + " --out " + cap + " -q > /dev/null 2> " +
                dir.file("err.txt")), 0) << slurp(dir.file("err.txt"));
  ASSERT_EQ(run(std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + cap + " --technique baseline --out " +
                out + " -q > /dev/null 2> " + dir.file("err2.txt")), 0) << slurp(dir.file("err2.txt"));
  EXPECT_EQ(count_files(out + "/frames"), 12u);
}

// `--out` never removes what mrgi did not create (OutputDir): a user's folder, even one holding
// a summary.json, and the capture being replayed are refused with exit 2 and left as they were,
// and nothing half-written is left behind.
TEST_F(ToolCommands, OutNeverReplacesWhatMrgiDidNotCreate) {
  test::TempDir dir("out-safety");
  const std::string capture = std::string(MRGI_SOURCE_DIR) + "/perf/suite/desk_spot";
  const std::string user = dir.file("user");
  std::filesystem::create_directories(user);
  std::ofstream(user + "/summary.json") << "{\"mine\": true}\n";
  const std::string replay = std::string("LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + capture +
                             " --technique baseline --level last --frames 1 -q --out ";
  EXPECT_EQ(run(replay + user + " > /dev/null 2> " + dir.file("err.txt")), 2);
  EXPECT_NE(slurp(dir.file("err.txt")).find("not written by mrgi"), std::string::npos) << slurp(dir.file("err.txt"));
  EXPECT_EQ(slurp(user + "/summary.json"), "{\"mine\": true}\n");
  EXPECT_FALSE(std::filesystem::exists(user + ".partial"));
  EXPECT_EQ(run(replay + capture + " > /dev/null 2> " + dir.file("err2.txt")), 2);
  EXPECT_TRUE(std::filesystem::exists(capture + "/capture.json"));
  // Its own output is replaced on the next run.
  const std::string out = dir.file("out");
  ASSERT_EQ(run(replay + out + " > /dev/null 2> " + dir.file("err3.txt")), 0) << slurp(dir.file("err3.txt"));
  ASSERT_EQ(run(replay + out + " > /dev/null 2> " + dir.file("err4.txt")), 0) << slurp(dir.file("err4.txt"));
  EXPECT_EQ(count_files(out + "/frames"), 1u);
}

}  // namespace
}  // namespace mrgi
