// The tool's live view (`mrgi replay --view`) under a virtual X server (Xvfb): the window shows
// exactly the frame the replay writes (the X server's copy of the window against the PNG), and
// the view's errors: no display, a screenshot without a view. Skipped with a message where Xvfb
// (xvfb-run) is not installed or the tool was built without the view (GLFW).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "mrgi/image.h"
#include "test_support.h"

namespace mrgi {
namespace {

int run(const std::string& cmd) { return test::run_command(cmd); }
std::string slurp(const std::string& path) { return test::read_text(path); }

const std::string kReplay = std::string("env LP_NUM_THREADS=2 timeout 300 ") + MRGI_TOOL + " replay " + MRGI_SOURCE_DIR +
                            "/data/sample --technique baseline -q";

class ToolView : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
    test::TempDir probe("view_probe");
    run("env -u DISPLAY " + kReplay + " --frames 1 --out " + probe.file("out") + " --view > /dev/null 2> " +
        probe.file("err.txt"));
    if (slurp(probe.file("err.txt")).find("built without the live view") != std::string::npos)
      GTEST_SKIP() << "this mrgi was built without the live view (libglfw3-dev)";
  }
  static bool have_xvfb() { return run("command -v xvfb-run > /dev/null 2>&1") == 0; }
};

TEST_F(ToolView, TheWindowShowsExactlyTheFrameTheReplayWrites) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb): no X server to open the window on";
  test::TempDir dir("view");
  const std::string out = dir.file("out"), shot = dir.file("shot.png");
  ASSERT_EQ(run("xvfb-run -a -s '-screen 0 1600x1200x24' " + kReplay + " --level medium --frames 4 --out " + out +
                " --view --view-screenshot " + shot + " > /dev/null 2> " + dir.file("err.txt")),
            0)
      << slurp(dir.file("err.txt"));
  auto seen = load_png_rgb8(shot);
  auto written = load_png_rgba8(out + "/frames/000003.png");  // alpha: the virtual mask
  ASSERT_TRUE(seen.ok()) << seen.error().message;
  ASSERT_TRUE(written.ok()) << written.error().message;
  ASSERT_EQ(seen->width, written->width);
  ASSERT_EQ(seen->height, written->height);
  size_t differing = 0;
  for (size_t p = 0; p < size_t(seen->width) * size_t(seen->height); ++p)
    for (size_t c = 0; c < 3; ++c) differing += seen->data[3 * p + c] != written->data[4 * p + c];
  EXPECT_EQ(differing, 0u) << "the window's pixels differ from the written frame in " << differing << " values";
}

// live --view on a capture folder, with and without --out: the window shows the last frame live
// writes; without --out nothing is written and the run still ends cleanly.
TEST_F(ToolView, LiveViewShowsTheLastFrameWithOrWithoutOutput) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb): no X server to open the window on";
  test::TempDir dir("live_view");
  const std::string live = std::string("xvfb-run -a -s '-screen 0 1600x1200x24' env LP_NUM_THREADS=2 timeout 300 ") +
                           MRGI_TOOL + " live " + MRGI_SOURCE_DIR + "/data/sample --level low --frames 3 -q --view";
  const std::string out = dir.file("out"), shot = dir.file("shot.png");
  ASSERT_EQ(run(live + " --out " + out + " --view-screenshot " + shot + " > /dev/null 2> " + dir.file("err.txt")), 0)
      << slurp(dir.file("err.txt"));
  auto seen = load_png_rgb8(shot);
  auto written = load_png_rgba8(out + "/frames/000002.png");
  ASSERT_TRUE(seen.ok() && written.ok());
  ASSERT_EQ(seen->width, written->width);
  size_t differing = 0;
  for (size_t p = 0; p < size_t(seen->width) * size_t(seen->height); ++p)
    for (size_t c = 0; c < 3; ++c) differing += seen->data[3 * p + c] != written->data[4 * p + c];
  EXPECT_EQ(differing, 0u);
  ASSERT_EQ(run(live + " --view-screenshot " + dir.file("shot2.png") + " > /dev/null 2> " + dir.file("err2.txt")), 0)
      << slurp(dir.file("err2.txt"));
  EXPECT_TRUE(std::filesystem::exists(dir.file("shot2.png")));
  EXPECT_EQ(run(std::string("env LP_NUM_THREADS=2 timeout 60 ") + MRGI_TOOL + " live " + MRGI_SOURCE_DIR +
                "/data/sample --frames 1 -q > /dev/null 2> " + dir.file("err3.txt")),
            2);
  EXPECT_NE(slurp(dir.file("err3.txt")).find("--out is required (or --view"), std::string::npos) << slurp(dir.file("err3.txt"));
}

// The keys, pressed with xdotool while the replay is paused (Space) so that each acts on a known
// frame: [ a cheaper level from the next frame on, T the next technique, S the camera frame beside
// the composite (the window twice as wide).
TEST_F(ToolView, TheKeysChangeLevelTechniqueAndSideBySide) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb)";
  if (run("command -v xdotool > /dev/null 2>&1") != 0) GTEST_SKIP() << "xdotool not installed (Debian: xdotool): no keys to press";
  test::TempDir dir("view_keys");
  const std::string out = dir.file("out"), shot = dir.file("shot.png"), err = dir.file("err.txt");
  std::ofstream script(dir.file("keys.sh"));
  script << kReplay << " --level medium --frames 8 --out " << out << " --view --view-screenshot " << shot << " 2> " << err
         << " &\n"
         << "pid=$!\n"
         << "for i in $(seq 300); do w=$(xdotool search --name 'mrgi replay' 2>/dev/null | head -1); [ -n \"$w\" ] && break; sleep 0.1; done\n"
         << "[ -n \"$w\" ] || { kill $pid; exit 3; }\n"
         << "frame() { xdotool getwindowname $w | sed -n 's/.*| frame \\([0-9]*\\) .*/\\1/p'; }\n"
         << "xdotool key --window $w space bracketleft; sleep 0.3; f=$(frame); xdotool key --window $w space\n"
         // Until a frame after the one that took the level has been shown (the title says which).
         << "for i in $(seq 600); do n=$(frame); [ -n \"$n\" ] && [ \"$n\" -ge $((f + 2)) ] && break; sleep 0.05; done\n"
         << "xdotool key --window $w space t s space\n"
         << "wait $pid\n";
  script.close();
  ASSERT_EQ(run("xvfb-run -a -s '-screen 0 1600x1200x24' bash " + dir.file("keys.sh") + " > /dev/null 2>&1"), 0)
      << slurp(err);
  const std::string log = slurp(err);
  EXPECT_NE(log.find("mrgi: view: technique ssrt from frame"), std::string::npos) << log;
  const std::string stats = slurp(out + "/stats.json");
  EXPECT_NE(stats.find("\"level\": 2"), std::string::npos) << "no frame at the cheaper level";
  auto seen = load_png_rgb8(shot);
  ASSERT_TRUE(seen.ok()) << seen.error().message;
  EXPECT_EQ(seen->width, 2 * 640) << "side by side: the camera frame beside the composite";
}

TEST_F(ToolView, NoDisplayIsAClearErrorAndWritesNothing) {
  test::TempDir dir("view_no_display");
  const std::string out = dir.file("out");
  EXPECT_EQ(run("env -u DISPLAY -u WAYLAND_DISPLAY " + kReplay + " --frames 2 --out " + out + " --view > /dev/null 2> " +
                dir.file("err.txt")),
            1);
  EXPECT_NE(slurp(dir.file("err.txt")).find("no display to open a window on"), std::string::npos)
      << slurp(dir.file("err.txt"));
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ToolView, AScreenshotWithoutTheViewIsRefused) {
  test::TempDir dir("view_shot_alone");
  EXPECT_EQ(run(kReplay + " --frames 1 --out " + dir.file("out") + " --view-screenshot " + dir.file("s.png") +
                " > /dev/null 2> " + dir.file("err.txt")),
            2);
  EXPECT_NE(slurp(dir.file("err.txt")).find("--view-screenshot: only with --view"), std::string::npos)
      << slurp(dir.file("err.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
}

}  // namespace
}  // namespace mrgi
