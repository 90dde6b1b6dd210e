// A suite capture held in memory for the bench and the load test (inputs preloaded, as a live
// device's sensor delivers them), and the run's frames built from it before timing starts.
#pragma once
#include <optional>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/image.h"
#include "mrgi/perf/suite.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {

struct LoadedScene {
  SuiteScene suite;
  CaptureInfo info;
  SceneDesc scene;
  std::vector<InputFrame> frames;
  std::vector<std::optional<ImageRGB8>> references;
  std::vector<std::optional<ImageU8>> masks;
  double frame_interval_s = 1.0 / 30.0;
};

Expected<LoadedScene> load_scene(const SuiteScene& s);

// Replay order forth and back: 0..n-1, n-2..1, 0..; keeps motion continuous for temporal filters.
size_t ping_pong(size_t k, size_t n);

// Frame k is capture frame ping_pong(k) with index k and timestamps continued; the run holds
// frames first .. first + count - 1 (a runtime fed several runs takes them one after the other).
std::vector<InputFrame> preload_run(const LoadedScene& l, size_t count, size_t first = 0);

}  // namespace mrgi::perf
