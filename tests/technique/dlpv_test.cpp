// The dlpv technique end to end on the synthetic scene (synthetic_scene.h) with Vulkan validation
// on (a message fails process()/flush()): every level runs, says what it leaves out, lights the
// virtual boxes and takes light away from the real floor (the delta volume's antiradiance: the
// boxes block the lamp). Accuracy against path-traced references is the bench's (perf/).
#include <gtest/gtest.h>

#include <cmath>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

float lin(uint8_t c) { return shader::srgb_decode1(float(c) / 255.0f); }

TEST(Dlpv, EveryLevelLightsTheObjectAndDarkensTheFloorWithValidationOn) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  for (int level = 0; level < 5; ++level) {
    SCOPED_TRACE(level);
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = "dlpv";
    s.level = level;
    auto rt = create_runtime(s, scene.cameras(), scene.scene);
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    std::vector<FrameOutput> outs;
    std::vector<InputFrame> inputs;
    for (int i = 0; i < 3; ++i) {
      inputs.push_back(scene.frame(i));
      auto o = (*rt)->process(inputs.back());
      ASSERT_TRUE(o.ok()) << o.error().message;
      for (auto& f : *o) outs.push_back(std::move(f));
    }
    auto rest = (*rt)->flush();
    ASSERT_TRUE(rest.ok()) << rest.error().message;
    for (auto& f : *rest) outs.push_back(std::move(f));
    ASSERT_EQ(outs.size(), 3u);
    const FrameOutput& out = outs.back();
    const InputFrame& in = inputs.back();
    // The cheaper levels say they shade virtual pixels without V^rho.
    bool rho_note = false;
    for (const std::string& k : out.stats.skipped) rho_note |= k.rfind("dlpv rho volume", 0) == 0;
    EXPECT_EQ(rho_note, level >= 3);
    // Virtual pixels lit (not black); floor pixels in the boxes' shadow (the lamp blocked by a
    // virtual box, not by the real one) darker than the camera saw them: the delta volume's
    // antiradiance. (How dark, against the path-traced reference, is the bench's figure.)
    double virtual_sum = 0.0, shadow_change = 0.0;
    int virtual_n = 0, shadow_n = 0;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const SurfaceHit hit = scene.trace(u, v, true);
        const size_t i = (size_t(v) * w + u) * 3, o = (size_t(v) * w + u) * 4;  // RGB8 in, RGBA8 out
        double y_out = 0.0, y_in = 0.0;
        for (int c = 0; c < 3; ++c) {
          y_out += lin(out.image.data[o + c]);
          y_in += lin(in.color.data[i + c]);
        }
        if (hit.kind == SurfaceKind::Virtual) {
          virtual_sum += y_out;
          ++virtual_n;
        } else if (hit.kind == SurfaceKind::Floor && scene.blocked_by_virtual(hit.point) &&
                   !scene.blocked_by_real(hit.point)) {
          shadow_change += y_out - y_in;
          ++shadow_n;
        }
      }
    ASSERT_GT(virtual_n, 0);
    ASSERT_GT(shadow_n, 0);
    EXPECT_GT(virtual_sum / virtual_n, 0.05);
    EXPECT_LT(shadow_change / shadow_n, 0.0) << "the floor in the boxes' shadow must lose light";
  }
}

}  // namespace
}  // namespace mrgi::test
