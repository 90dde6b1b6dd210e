// Harnesses shared by the GI techniques' tests (dlpv_test.cpp, dir_test.cpp). The 1,000-frame
// stress (no NaN, no energy growth over 1,000 frames), shared by dlpv_test.cpp and dir_test.cpp: a
// variant of the synthetic scene run at one level for `n` frames whose depth alternates by 1 cm
// (beyond the reuse tolerance of gi/input_reuse.h, so the light-dependent work is rebuilt every
// frame), keeping frames 0-59 and the last 102, and the notes it saw. check_stress_outcome() then
// asks that nothing was reused, that frames of the same input are equal bit for bit once the
// reconstruction's filter has settled (the last two against the 100th before them) and that the
// mean output light of the last 20 frames is within 1 % of frames 40-59's. Why frames 40-59 and not
// the first frames: a technique that carries light from one frame to the next (dir's bounce VPLs)
// draws each frame's VPLs from the last frame's by importance, so its first tens of frames may
// still switch between nearby selections (one VPL near a wall under a lamp at 1e6 saturates a few
// pixels: a 4 % change of a 64 x 48 image's mean at frame 20, constant from there to frame 1,000).
// Growth of 1.1e-5 a frame reaches 1 % over the 940 frames between the two windows.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "mrgi/runtime.h"
#include "../../shaders/shared/mrgi_shared.h"
#include "synthetic_scene.h"

namespace mrgi::test {

struct StressVariant {
  const char* name;
  glm::vec3 base;                 // the virtual objects' base colour (black: they reflect nothing)
  void (*edit)(SyntheticScene&);  // the variant's change to the scene
  float metallic = 0.0f, roughness = 1.0f;  // the virtual objects' glTF factors
  const char* knob = nullptr;               // a quality knob set for the run (RuntimeSettings::knobs)
  double knob_value = 0.0;
};

struct StressOutcome {
  int frames = 0;                   // asked for
  int seen = 0;                     // outputs that came back
  bool reused = false;              // a frame carried `reuse_note`
  bool inside_note = false;         // a frame said a lamp was inside the sphere its maps fit
  std::vector<FrameOutput> kept;    // by frame index; only 0-59 and the last 102 are filled
};

inline double stress_mean_light(const FrameOutput& o) {
  double sum = 0.0;
  for (size_t k = 0; k < o.image.data.size(); ++k)
    if (k % 4 != 3) sum += shader::srgb_decode1(float(o.image.data[k]) / 255.0f);
  return sum / double(std::max<size_t>(o.image.data.size(), 1));
}

// Fatal failures (a frame refused) return early: the caller checks HasFatalFailure().
inline void run_stress(const StressVariant& v, const std::string& folder, const std::string& technique, int level,
                       const std::string& reuse_note, int n, StressOutcome& out) {
  SyntheticScene scene = SyntheticScene::create(folder, glm::vec3(0.0f), v.base, v.metallic, v.roughness);
  v.edit(scene);
  RuntimeSettings s;
  s.technique = technique;
  s.level = level;
  if (v.knob) s.knobs = {{v.knob, v.knob_value}};
  auto rt = create_runtime(s, scene.cameras(), scene.scene);
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  InputFrame frames[2] = {scene.frame(0), scene.frame(1)};
  for (uint16_t& d : frames[1].depth.data)
    if (d != 0) d = uint16_t(d + uint16_t(scene.depth_scale / 100.0));
  out.frames = n;
  out.kept.assign(size_t(n), FrameOutput{});
  auto take = [&](std::vector<FrameOutput>& outs) {
    for (FrameOutput& o : outs) {
      for (const std::string& note : o.stats.skipped) {
        out.reused |= note.rfind(reuse_note, 0) == 0;
        out.inside_note |= note.find("inside its sphere") != std::string::npos;
      }
      const int64_t k = o.stats.frame_index;
      if (k >= 0 && k < n && (k < 60 || k >= n - 102)) out.kept[size_t(k)] = std::move(o);
      ++out.seen;
    }
  };
  for (int k = 0; k < n; ++k) {
    InputFrame f = frames[k % 2];
    f.index = k;
    auto o = (*rt)->process(f);
    ASSERT_TRUE(o.ok()) << "frame " << k << ": " << o.error().message;
    take(*o);
  }
  auto rest = (*rt)->flush();
  ASSERT_TRUE(rest.ok()) << rest.error().message;
  take(*rest);
}

inline void check_stress_outcome(const StressOutcome& o) {
  const int n = o.frames;
  ASSERT_EQ(o.seen, n);
  EXPECT_FALSE(o.reused) << "every frame must rebuild its light-dependent work here";
  for (int k = n - 2; k < n; ++k)
    EXPECT_TRUE(o.kept[size_t(k)].image.data == o.kept[size_t(k - 100)].image.data)
        << "frame " << k << " differs from frame " << k - 100 << " (same input)";
  ASSERT_GE(n, 162) << "the settled window (frames 40-59) must end before the last 102 frames";
  double early = 0.0, late = 0.0;
  for (int k = 40; k < 60; ++k) early += stress_mean_light(o.kept[size_t(k)]);
  for (int k = n - 20; k < n; ++k) late += stress_mean_light(o.kept[size_t(k)]);
  EXPECT_GT(early, 0.0);
  EXPECT_NEAR(late / early, 1.0, 0.01) << "mean light of the last 20 frames against frames 40-59";
}

// The reuse skip of the GI techniques (gi/input_reuse.h), shared by dlpv_test.cpp and
// dir_test.cpp: five frames of the synthetic scene with validation on, one frame in flight (each
// process() returns the previous frame, so outputs come in order): frame 0, frame 1 (identical
// input), frame 2 with the depth 1.8 mm off everywhere (within the 2 mm tolerance), frame 3 with
// it 1 cm off, frame 4 with the camera 5 cm to the side. Frames 1 and 2 must carry `reuse_note`,
// the others not; frame 1 must equal frame 0 bit for bit; frame 2 must stay within 4/255 per
// channel of a fresh runtime that computes it (the largest change is printed).
inline void check_reuse_within_tolerance(const std::string& folder, const std::string& technique, int level,
                                         const std::string& reuse_note) {
  const SyntheticScene scene = SyntheticScene::create(folder);
  auto make = [&]() {
    RuntimeSettings s;
    s.device.validate = true;
    s.technique = technique;
    s.level = level;
    s.frames_in_flight = 1;
    return create_runtime(s, scene.cameras(), scene.scene);
  };
  auto shifted_depth = [&](int64_t index, int units) {
    InputFrame f = scene.frame(index);
    for (uint16_t& d : f.depth.data)
      if (d != 0) d = uint16_t(int(d) + units);
    return f;
  };
  auto run_all = [](Runtime& rt, const std::vector<InputFrame>& in, std::vector<FrameOutput>& out) {
    for (const InputFrame& f : in) {
      auto o = rt.process(f);
      ASSERT_TRUE(o.ok()) << o.error().message;
      for (auto& x : *o) out.push_back(std::move(x));
    }
    auto rest = rt.flush();
    ASSERT_TRUE(rest.ok()) << rest.error().message;
    for (auto& x : *rest) out.push_back(std::move(x));
  };
  InputFrame moved = scene.frame(4);
  moved.pose->translation.x += 0.05;
  const int mm = int(scene.depth_scale / 1000.0);
  const std::vector<InputFrame> frames = {scene.frame(0), scene.frame(1), shifted_depth(2, 9 * mm / 5),
                                          shifted_depth(3, 10 * mm), moved};
  auto rt = make();
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  std::vector<FrameOutput> outs;
  run_all(**rt, frames, outs);
  if (::testing::Test::HasFatalFailure()) return;
  ASSERT_EQ(outs.size(), frames.size());
  auto reused = [&](const FrameOutput& o) {
    for (const std::string& k : o.stats.skipped)
      if (k.rfind(reuse_note, 0) == 0) return true;
    return false;
  };
  const bool want[] = {false, true, true, false, false};
  for (size_t i = 0; i < outs.size(); ++i) EXPECT_EQ(reused(outs[i]), want[i]) << "frame " << i;
  EXPECT_TRUE(outs[1].image.data == outs[0].image.data) << "a reused frame differs from the recomputed one";
  auto fresh = make();
  ASSERT_TRUE(fresh.ok()) << fresh.error().message;
  std::vector<FrameOutput> recomputed;
  run_all(**fresh, {frames[2]}, recomputed);
  if (::testing::Test::HasFatalFailure()) return;
  ASSERT_EQ(recomputed.size(), 1u);
  EXPECT_FALSE(reused(recomputed[0]));
  int worst = 0;
  for (size_t k = 0; k < recomputed[0].image.data.size(); ++k)
    worst = std::max(worst, std::abs(int(recomputed[0].image.data[k]) - int(outs[2].image.data[k])));
  std::printf("%s reuse at 1.8 mm of depth change: largest change %d / 255\n", technique.c_str(), worst);
  EXPECT_LE(worst, 4) << "reuse within tolerance moved a pixel by more than 4/255";
}

}  // namespace mrgi::test
