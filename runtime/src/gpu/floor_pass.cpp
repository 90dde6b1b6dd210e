#include "gpu/floor_pass.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "gpu/shaders.h"

namespace mrgi::gpu {

Expected<FloorPass> FloorPass::create(FrameGraph& graph) {
  auto pipeline = load_compute_pipeline(graph.context(), "floor.comp", {});  // layout from the shader
  if (!pipeline) return pipeline.error();
  FloorPass f;
  f.pipeline_ = std::move(*pipeline);
  for (int i = 0; i < 2; ++i) {
    ImageDesc d;
    d.name = i == 0 ? "floor.a" : "floor.b";
    d.format = VK_FORMAT_R8G8B8A8_UNORM;
    d.size_mode = SizeMode::OutputRelative;
    d.follows_render_scale = false;
    // Each image is read one frame and written the next: its contents must carry over.
    d.history = true;
    auto h = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                       VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    if (!h) return h.error();
    f.images_[i] = *h;
  }
  return f;
}

void FloorPass::add_to(FrameGraph& graph) {
  const ImageHandle src = images_[flip_], dst = images_[1 - flip_];
  const Pipeline* pipeline = &*pipeline_;
  graph.add_shader_pass(
      "floor", PassKind::Compute, *pipeline,
      [&](ShaderPassBuilder& b) {
        b.bind("src_image", src);
        b.bind("dst_image", dst);
      },
      [dst, pipeline](VkCommandBuffer cmd, PassContext& ctx) {
        const VkExtent2D e = ctx.extent(dst);
        const int32_t extent[2] = {int32_t(e.width), int32_t(e.height)};
        dispatch_2d(cmd, *pipeline, extent, sizeof extent, e.width, e.height);
      });
  graph.mark_output(dst);
  flip_ = 1 - flip_;
}

Expected<FloorTimer> FloorTimer::create(Context& context, uint32_t width, uint32_t height, uint32_t warmup) {
  if (width == 0 || height == 0) return fail(ErrorKind::BadUsage, "floor pass: width and height must be > 0");
  FrameGraphSettings fs;
  fs.max_output_width = width;
  fs.max_output_height = height;
  fs.frames_in_flight = 1;  // sample() waits for its frames anyway
  fs.max_passes = 4;
  auto graph = FrameGraph::create(context, fs);
  if (!graph) return graph.error();
  auto pass = FloorPass::create(**graph);
  if (!pass) return pass.error();
  // Defined contents (a gradient) so the pass reads real data, not whatever memory held.
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
  // Timed as the bench's profiled passes are (submitted alone, host clock from submit to fence),
  // so a pass's ratio to the floor compares like with like.
  MRGI_TRY((*graph)->set_profiling(true));
  FloorTimer timer(std::move(graph).value(), std::move(pass).value());
  std::vector<double> discarded;
  MRGI_TRY(timer.sample(warmup, discarded));
  return timer;
}

Status FloorTimer::sample(uint32_t frames, std::vector<double>& samples_ms) {
  size_t got = 0;
  auto take = [&](const FrameTimings& t) {
    for (const PassTiming& p : t.passes)
      if (p.name == "floor") {
        samples_ms.push_back(p.gpu_ms);
        ++got;
      }
  };
  for (uint32_t i = 0; i < frames; ++i) {
    auto done = graph_->begin_frame();
    if (!done) return done.error();
    if (*done) take(**done);
    pass_.add_to(*graph_);
    MRGI_TRY(graph_->submit());
  }
  auto rest = graph_->flush();
  if (!rest) return rest.error();
  for (const FrameTimings& t : *rest) take(t);
  if (got != frames)
    return fail(ErrorKind::Internal, "floor pass: " + std::to_string(got) + " timings came back for " +
                                         std::to_string(frames) + " frames");
  return ok_status();
}

Expected<FloorMeasurement> measure_floor_pass(Context& context, uint32_t width, uint32_t height, uint32_t frames,
                                              uint32_t warmup) {
  if (width == 0 || height == 0 || frames == 0)
    return fail(ErrorKind::BadUsage, "measure_floor_pass: width, height and frames must be > 0");
  auto timer = FloorTimer::create(context, width, height, warmup);
  if (!timer) return timer.error();
  FloorMeasurement m;
  MRGI_TRY(timer->sample(frames, m.samples_ms));
  std::vector<double> sorted = m.samples_ms;
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  m.median_ms = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  m.min_ms = sorted.front();
  m.max_ms = sorted.back();
  return m;
}

}  // namespace mrgi::gpu
