// Edges at the output resolution: whatever the internal scale, the real/virtual mask the runtime
// returns is the virtual objects' coverage at the output's pixels (recon::VirtualGBuffer's
// output coverage), not the internal G-buffer's texels stretched. Checked against the synthetic
// scene's analytic mask (a ray per output pixel centre), with Vulkan validation on, for every
// technique at its best level and internal scale 0.5 (and 1, the G-buffer's own mask): a pixel
// may disagree only where the analytic mask changes between it and a 4-neighbour (the
// rasteriser's and the ray's rounding differ on edges through a pixel centre), and on at most a
// tenth of those edge pixels. The stretched 0.5-scale mask of the internal texels (what compose
// showed before the output coverage) differs on 54 of the scene's pixels, and fails.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace {
using namespace mrgi;
using mrgi::test::SurfaceKind;
using mrgi::test::SyntheticScene;

struct MaskCheck {
  int analytic = 0;   // virtual pixels of the analytic mask
  int edge = 0;       // pixels where the analytic mask changes towards a 4-neighbour
  int wrong = 0;      // pixels that differ from it
  int off_edge = 0;   // of those, pixels no analytic edge touches
};

MaskCheck check_mask(const SyntheticScene& scene, const Image<uint8_t, 1>& mask) {
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  std::vector<char> truth(size_t(w) * h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) truth[size_t(v) * w + u] = scene.trace(u, v, true).kind == SurfaceKind::Virtual;
  MaskCheck c;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const char t = truth[size_t(v) * w + u];
      c.analytic += t;
      bool edge = false;
      const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int x = u + du[k], y = v + dv[k];
        if (x >= 0 && y >= 0 && x < w && y < h && truth[size_t(y) * w + x] != t) edge = true;
      }
      c.edge += edge;
      if ((mask.data[size_t(v) * w + u] != 0) == (t != 0)) continue;
      ++c.wrong;
      c.off_edge += !edge;
    }
  return c;
}

TEST(OutputEdges, MaskAndObjectEdgesAtHalfInternalScaleMatchTheOutputResolution) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  for (const std::string& technique : technique_names()) {
    ImageRGBA8 full;
    for (const double scale : {1.0, 0.5}) {
      SCOPED_TRACE(technique + " internal_scale " + std::to_string(scale));
      RuntimeSettings s;
      s.technique = technique;
      s.level = 0;
      s.device.validate = true;
      s.knobs = {{"internal_scale", scale}};
      const std::vector<FrameOutput> outs = test::run_synthetic_frames(scene, s, 2);
      ASSERT_EQ(outs.size(), 2u);
      const MaskCheck c = check_mask(scene, outs.back().virtual_mask);
      std::printf("%s scale %.2f: %d analytic virtual pixels, %d edge pixels, %d differ, %d of them off an edge\n",
                  technique.c_str(), scale, c.analytic, c.edge, c.wrong, c.off_edge);
      EXPECT_GT(c.analytic, 100);
      EXPECT_EQ(c.off_edge, 0);
      EXPECT_LE(c.wrong, c.edge / 10);
      if (scale == 1.0) {
        full = outs.back().image;
        continue;
      }
      ASSERT_EQ(full.data.size(), outs.back().image.data.size());
      // The colour of the object's own edge pixels: up-sampled from the object's texels only,
      // so close to the full-scale frame's: 5.8-11.1 levels of 255 on average here, where a
      // plain bilinear up-sampling, which mixes in the floor's light, gives 18.6-22.4.
      double sum = 0.0;
      int n = 0;
      const int w = scene.intrinsics.width;
      for (int v = 1; v + 1 < scene.intrinsics.height; ++v)
        for (int u = 1; u + 1 < w; ++u) {
          const size_t i = size_t(v) * w + u;
          if (!outs.back().virtual_mask.data[i]) continue;
          const bool edge = !outs.back().virtual_mask.data[i - 1] || !outs.back().virtual_mask.data[i + 1] ||
                            !outs.back().virtual_mask.data[i - w] || !outs.back().virtual_mask.data[i + w];
          if (!edge) continue;
          for (int ch = 0; ch < 3; ++ch) sum += std::abs(int(outs.back().image.data[4 * i + ch]) - int(full.data[4 * i + ch]));
          n += 3;
        }
      std::printf("  object edge pixels: mean |0.5 - 1| %.2f levels over %d values\n", n ? sum / n : 0.0, n);
      ASSERT_GT(n, 100);
      EXPECT_LT(sum / n, 14.0);
    }
  }
}

}  // namespace
