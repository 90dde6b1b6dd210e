// The floor pass: a trivial full-resolution read-and-write compute pass (one imageLoad and one
// imageStore per pixel of an RGBA8 image pair). Every measured time is also reported as a
// ratio to it, which makes timings comparable across machines.
#pragma once
#include <memory>
#include <cstdint>
#include <vector>

#include "gpu/context.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gpu {

class FloorPass {
 public:
  // Allocates the image pair (output-relative, scale 1) in `graph` and the pipeline.
  static Expected<FloorPass> create(FrameGraph& graph);
  // Adds the pass "floor" reading one image and writing the other (alternating every frame),
  // marks the written one as output.
  void add_to(FrameGraph& graph);
  ImageHandle source() const { return images_[flip_]; }
  ImageHandle target() const { return images_[1 - flip_]; }

 private:
  PipelineHandle pipeline_;
  ImageHandle images_[2];
  uint32_t flip_ = 0;
};

struct FloorMeasurement {
  double median_ms = 0.0;
  double min_ms = 0.0;
  double max_ms = 0.0;
  std::vector<double> samples_ms;
};

// The floor pass kept ready at one size in a graph of its own, so a caller (the bench) can take
// floor samples between the frames of a run: the floor then sees the same machine load as the
// frames it is compared with.
class FloorTimer {
 public:
  // Allocates the graph and the pass for width x height, fills the source with a gradient (the
  // pass must read defined data) and runs `warmup` unmeasured frames.
  static Expected<FloorTimer> create(Context& context, uint32_t width, uint32_t height, uint32_t warmup);
  // Runs `frames` floor frames, waits for them, and appends each one's GPU ms to `samples_ms`.
  Status sample(uint32_t frames, std::vector<double>& samples_ms);

 private:
  FloorTimer(std::unique_ptr<FrameGraph> graph, FloorPass pass) : graph_(std::move(graph)), pass_(std::move(pass)) {}
  std::unique_ptr<FrameGraph> graph_;
  FloorPass pass_;
};

// Runs the floor pass `frames` times at width x height (after `warmup` frames not counted) in a
// graph of its own (a FloorTimer), and returns the GPU times of the pass.
Expected<FloorMeasurement> measure_floor_pass(Context& context, uint32_t width, uint32_t height,
                                              uint32_t frames = 20, uint32_t warmup = 3);

}  // namespace mrgi::gpu
