// The floor pass (runtime/src/gpu/floor_pass.h) kept ready at one size so the bench can take a
// few floor samples between the frames of a run: the floor then sees the same machine load as the
// frames it is compared with. measure_floor_pass() builds a graph per call; this keeps one.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "gpu/context.h"
#include "gpu/floor_pass.h"
#include "gpu/frame_graph.h"
#include "mrgi/expected.h"

namespace mrgi::perf {

class FloorTimer {
 public:
  // Allocates the graph and the pass for width x height and runs `warmup` unmeasured frames.
  static Expected<FloorTimer> create(gpu::Context& context, uint32_t width, uint32_t height, uint32_t warmup);
  // Runs `frames` floor frames, waits for them, and appends each one's GPU ms to `samples_ms`.
  Status sample(uint32_t frames, std::vector<double>& samples_ms);

 private:
  FloorTimer(std::unique_ptr<gpu::FrameGraph> graph, gpu::FloorPass pass)
      : graph_(std::move(graph)), pass_(std::move(pass)) {}
  std::unique_ptr<gpu::FrameGraph> graph_;
  gpu::FloorPass pass_;
};

}  // namespace mrgi::perf
