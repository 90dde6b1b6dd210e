// Replays a capture with references through the public runtime (validation layers on) and pools
// the error figures over its frames, as `mrgi replay` does; the golden tests use it. When the
// capture has environment frames, each output's light estimate (if the technique has one) is
// compared with the environment's dominant direction.
#pragma once
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "mrgi/light_estimate.h"
#include "mrgi/metrics.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi::test {

struct ReplayResult {
  RdeReport pooled;
  bool any = false;
  std::vector<double> light_error_deg;  // per frame with an estimate and an environment image
};

// `undeclared_light`: scene.json's lamps and environment are dropped, so the runtime lights the
// scene from what it estimates (the light stage's probeless source), as an app that declares
// nothing; the environment frames still serve as the truth for the direction error.
// `accumulate_views`: RuntimeSettings::light_accumulate_views (the probeless estimate kept over
// the views, or each view's own).
inline ReplayResult replay_capture(const std::string& path, const std::string& technique, int level,
                                   bool undeclared_light = false, bool accumulate_views = true) {
  ReplayResult g;
  auto capture = CaptureReader::open(path);
  EXPECT_TRUE(capture.ok()) << (capture.ok() ? "" : capture.error().message);
  if (!capture.ok()) return g;
  const CaptureInfo& info = capture->info();
  SceneDesc scene = *capture->scene();
  const double env_intensity = scene.environment.present ? scene.environment.intensity : 1.0;
  if (undeclared_light) {
    scene.lights.clear();
    scene.environment = EnvironmentDesc{};
  }
  RuntimeSettings s;
  s.device.validate = true;
  s.technique = technique;
  s.level = level;
  s.exposure = info.exposure;
  s.light_accumulate_views = accumulate_views;
  auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                           scene);
  EXPECT_TRUE(rt.ok()) << (rt.ok() ? "" : rt.error().message);
  if (!rt.ok()) return g;
  std::vector<ImageRGB8> cameras(capture->frame_count());
  std::vector<std::optional<LightEstimate>> truth(capture->frame_count());
  auto consume = [&](Expected<std::vector<FrameOutput>>&& outs) {
    ASSERT_TRUE(outs.ok()) << outs.error().message;  // includes any validation message
    for (const FrameOutput& o : *outs) {
      const size_t i = size_t(o.stats.frame_index);
      auto ref = capture->read_reference(i);
      auto mask = capture->read_reference_mask(i);
      ASSERT_TRUE(ref.ok() && mask.ok());
      auto r = measure_error(o.image, cameras[i], *ref, &*mask);
      ASSERT_TRUE(r.ok()) << r.error().message;
      if (!g.any) {
        g.pooled = *r;
        g.any = true;
      } else {
        g.pooled = pool(g.pooled, *r);
      }
      if (o.light && o.light->valid && truth[i])
        g.light_error_deg.push_back(direction_error_deg(*o.light, *truth[i]));
    }
  };
  for (size_t i = 0; i < capture->frame_count(); ++i) {
    auto f = capture->read_frame(i);
    EXPECT_TRUE(f.ok()) << f.error().message;
    if (!f.ok()) return g;
    f->index = int64_t(i);
    cameras[i] = f->color;
    if (f->env && info.env_camera) {
      auto t = light_from_environment(*f->env, *info.env_camera, env_intensity);
      EXPECT_TRUE(t.ok());
      if (t.ok()) truth[i] = *t;
    }
    consume((*rt)->process(*f));
  }
  consume((*rt)->flush());
  return g;
}

// Every frame of `capture` through a runtime made with `s`, outputs in `outs` (fatal failures
// through gtest: check HasFatalFailure() after).
inline void run_every_frame(CaptureReader& capture, const RuntimeSettings& s, std::vector<FrameOutput>& outs) {
  const CaptureInfo& info = capture.info();
  auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                           *capture.scene());
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  for (size_t i = 0; i < capture.frame_count(); ++i) {
    auto f = capture.read_frame(i);
    ASSERT_TRUE(f.ok());
    f->index = int64_t(i);
    auto o = (*rt)->process(*f);
    ASSERT_TRUE(o.ok()) << o.error().message;
    for (auto& x : *o) outs.push_back(std::move(x));
  }
  auto rest = (*rt)->flush();
  ASSERT_TRUE(rest.ok()) << rest.error().message;
  for (auto& x : *rest) outs.push_back(std::move(x));
}

}  // namespace mrgi::test
