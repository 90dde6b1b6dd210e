// Every quality knob of every technique at the ends of its span (RuntimeSettings::knobs), with
// Vulkan validation on: the best level with the knob at its smallest value and the cheapest
// level with it at its largest (each end against the other levels' settings), three frames
// each, on the synthetic scene. Each run must create, render without a validation message or
// error, and draw the virtual object; the ladder must report the knob's value at every level.
// A knob that is refused, unknown or out of its span gives BadUsage naming it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace {
using namespace mrgi;
using mrgi::test::SyntheticScene;

TEST(KnobSweep, EveryKnobRendersAtBothEndsOfItsSpan) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  int runs = 0;
  for (const std::string& technique : technique_names()) {
    const std::vector<QualityLevelInfo> ladder = *technique_ladder(technique);
    for (const QualityKnob& knob : ladder.front().knobs) {
      if (knob.min == knob.max) continue;  // fixed: nothing to sweep
      for (const bool at_max : {false, true}) {
        const double value = at_max ? knob.max : knob.min;
        SCOPED_TRACE(technique + " --knob " + knob.name + "=" + std::to_string(value));
        RuntimeSettings s;
        s.technique = technique;
        s.level = at_max ? int(ladder.size()) - 1 : 0;
        s.device.validate = true;
        s.knobs = {{knob.name, value}};
        // Pairs the ladder forbids (dir: bounce_vpls below vpls) move the other knob with it.
        if (technique == "dir" && knob.name == "vpls" && !at_max) s.knobs.push_back({"bounce_vpls", 0});
        if (technique == "dir" && knob.name == "bounce_vpls" && at_max) s.knobs.push_back({"vpls", 256});
        auto set = technique_ladder(technique, s.knobs);
        ASSERT_TRUE(set.ok()) << set.error().message;
        for (const QualityLevelInfo& l : *set)
          for (const QualityKnob& k : l.knobs)
            if (k.name == knob.name) {
              EXPECT_EQ(k.value, value) << l.name;
            }
        const std::vector<FrameOutput> outs = test::run_synthetic_frames(scene, s, 3);
        ASSERT_EQ(outs.size(), 3u);
        size_t virtual_pixels = 0;
        for (size_t i = 0; i < outs.back().virtual_mask.pixel_count(); ++i)
          virtual_pixels += outs.back().virtual_mask.data[i] != 0;
        EXPECT_GT(virtual_pixels, 20u) << "the object is not drawn";
        ++runs;
      }
    }
  }
  EXPECT_GT(runs, 40);  // the four techniques' knobs, two ends each
}

TEST(KnobSweep, RefusedKnobsNameThemselves) {
  mrgi::testing::TempDir dir;
  const SyntheticScene scene = SyntheticScene::create(dir.str());
  struct Case {
    const char* technique;
    KnobSetting knob;
    const char* says;
  };
  const Case cases[] = {
      {"dir", {"vpls", 512}, "outside 16..256"},
      {"dir", {"ism_size", 48}, "power of two"},
      {"dir", {"rsm_lamps", 1.5}, "whole number"},
      {"dir", {"bounce_vpls", 64}, "must be below vpls"},  // at the fastest level, vpls 16
      {"dir", {"env_parts", 8}, "outside 1..4"},
      {"dir", {"env_parts", 3}, "power of two"},
      {"baseline", {"vpls", 64}, "has no such knob"},
      {"dlpv", {"volume_cells", -1}, "outside 8..32"},
      {"ssrt", {"directions", std::nan("")}, "outside"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.technique) + " " + c.knob.name);
    RuntimeSettings s;
    s.technique = c.technique;
    s.knobs = {c.knob};
    auto rt = create_runtime(s, scene.cameras(), scene.scene);
    ASSERT_FALSE(rt.ok());
    EXPECT_EQ(rt.error().kind, ErrorKind::BadUsage);
    EXPECT_NE(rt.error().message.find(c.knob.name), std::string::npos) << rt.error().message;
    EXPECT_NE(rt.error().message.find(c.says), std::string::npos) << rt.error().message;
  }
}

}  // namespace
