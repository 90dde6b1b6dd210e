// The passthrough overlay (mrgi/overlay.h) of real frames: for baseline (shadows only) and dir
// (shadows and bounce light that brightens real pixels) on the golden desk capture, the overlay
// made from each output, blended over the camera frame the compositor would show, gives the
// composite within one 8-bit level (the overlay's own rounding; the stated bound is 2).
// Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "common/replay_capture.h"
#include "mrgi/overlay.h"
#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

const std::string kCapture = std::string(MRGI_SOURCE_DIR) + "/tests/data/golden_desk_160";

TEST(GoldenOverlay, BlendedOverTheCameraFrameItGivesTheComposite) {
  auto capture = CaptureReader::open(kCapture);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  for (const char* technique : {"baseline", "dir"}) {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = technique;
    s.level = 2;
    std::vector<FrameOutput> outs;
    test::run_every_frame(*capture, s, outs);
    if (HasFatalFailure()) return;
    ASSERT_EQ(outs.size(), capture->frame_count());
    size_t darkened = 0, brightened = 0, opaque = 0;
    for (size_t i = 0; i < outs.size(); ++i) {
      auto camera = capture->read_frame(i);
      ASSERT_TRUE(camera.ok());
      auto overlay = make_overlay(outs[i].image, outs[i].virtual_mask, camera->color);
      ASSERT_TRUE(overlay.ok()) << overlay.error().message;
      auto shown = blend_overlay(*overlay, camera->color);
      ASSERT_TRUE(shown.ok()) << shown.error().message;
      int worst = 0;
      for (size_t p = 0; p < shown->data.size() / 3; ++p) {
        for (int c = 0; c < 3; ++c)
          worst = std::max(worst,
                           std::abs(int(shown->data[3 * p + size_t(c)]) - int(outs[i].image.data[4 * p + size_t(c)])));
        const uint8_t* o = &overlay->data[4 * p];
        opaque += o[3] == 255;
        darkened += o[3] > 0 && o[3] < 255;
        brightened += o[3] < 255 && (o[0] > 0 || o[1] > 0 || o[2] > 0);
      }
      EXPECT_LE(worst, 1) << technique << " frame " << i;
    }
    std::printf("%s: %zu opaque, %zu darkening and %zu adding overlay pixels\n", technique, opaque, darkened,
                brightened);
    EXPECT_GT(opaque, 0u) << technique << ": the virtual object is opaque in the overlay";
    EXPECT_GT(darkened, 0u) << technique << ": its shadow darkens the passthrough";
  }
}

}  // namespace
}  // namespace mrgi
