#include "floor_timer.h"

#include <algorithm>
#include <string>

namespace mrgi::perf {

Expected<FloorTimer> FloorTimer::create(gpu::Context& context, uint32_t width, uint32_t height, uint32_t warmup) {
  if (width == 0 || height == 0) return fail(ErrorKind::BadUsage, "floor pass: width and height must be > 0");
  gpu::FrameGraphSettings fs;
  fs.max_output_width = width;
  fs.max_output_height = height;
  fs.frames_in_flight = 1;  // sample() waits for its frames anyway
  fs.max_passes = 4;
  auto graph = gpu::FrameGraph::create(context, fs);
  if (!graph.ok()) return graph.error();
  auto pass = gpu::FloorPass::create(**graph);
  if (!pass.ok()) return pass.error();
  // Defined contents (a gradient), as measure_floor_pass() uses, so the pass reads real data.
  std::vector<uint8_t> texels(size_t(width) * height * 4);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      uint8_t* p = &texels[(size_t(y) * width + x) * 4];
      p[0] = uint8_t(x * 255 / std::max(1u, width - 1));
      p[1] = uint8_t(y * 255 / std::max(1u, height - 1));
      p[2] = 128;
      p[3] = 255;
    }
  MRGI_TRY((*graph)->upload_image(pass->source(), texels.data(), texels.size()));
  FloorTimer timer(std::move(graph).value(), std::move(pass).value());
  std::vector<double> discarded;
  MRGI_TRY(timer.sample(warmup, discarded));
  return timer;
}

Status FloorTimer::sample(uint32_t frames, std::vector<double>& samples_ms) {
  size_t got = 0;
  auto take = [&](const gpu::FrameTimings& t) {
    for (const PassTiming& p : t.passes)
      if (p.name == "floor") {
        samples_ms.push_back(p.gpu_ms);
        ++got;
      }
  };
  for (uint32_t i = 0; i < frames; ++i) {
    auto done = graph_->begin_frame();
    if (!done.ok()) return done.error();
    if (*done) take(**done);
    pass_.add_to(*graph_);
    MRGI_TRY(graph_->submit());
  }
  auto rest = graph_->flush();
  if (!rest.ok()) return rest.error();
  for (const gpu::FrameTimings& t : *rest) take(t);
  if (got != frames)
    return fail(ErrorKind::Internal, "floor pass: " + std::to_string(got) + " timings came back for " +
                                         std::to_string(frames) + " frames");
  return ok_status();
}

}  // namespace mrgi::perf
