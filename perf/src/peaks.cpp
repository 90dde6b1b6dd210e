#include "mrgi/perf/peaks.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <glm/glm.hpp>

#include "gpu/context.h"
#include "gpu/floor_pass.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/perf/stats.h"

namespace mrgi::perf {
namespace {

constexpr uint32_t kPeakWidth = 640, kPeakHeight = 480;

struct Kernel {
  const char* name;
  const char* shader;
  std::vector<gpu::DescriptorBinding> bindings;
  uint32_t push_bytes;
};

// Times `record` as one profiled pass `repeats` times in a graph of its own.
Expected<std::vector<double>> time_pass(gpu::FrameGraph& graph, const std::string& pass_name,
                                        int repeats, const gpu::FrameGraph::SetupFn& setup,
                                        const gpu::FrameGraph::ExecuteFn& execute) {
  std::vector<double> ms;
  auto take = [&](const gpu::FrameTimings& t) {
    for (const PassTiming& p : t.passes)
      if (p.name == pass_name) ms.push_back(p.gpu_ms);
  };
  for (int i = 0; i < repeats + 1; ++i) {  // one warm-up run
    auto done = graph.begin_frame();
    if (!done) return done.error();
    if (*done && i > 1) take(**done);
    graph.add_pass(pass_name, gpu::PassKind::Compute, setup, execute);
    MRGI_TRY(graph.submit());
  }
  auto rest = graph.flush();
  if (!rest) return rest.error();
  for (const gpu::FrameTimings& t : *rest) take(t);
  if (ms.size() + 1 < size_t(repeats))
    return fail(ErrorKind::Internal, "peaks: " + std::to_string(ms.size()) + " timings of '" +
                                         pass_name + "' came back for " + std::to_string(repeats));
  return ms;
}

PeakResult result(const char* name, const std::vector<double>& ms, double work, const char* unit,
                  double unit_scale) {
  PeakResult r;
  r.name = name;
  r.median_ms = median(ms);
  r.min_ms = *std::min_element(ms.begin(), ms.end());
  r.work = work;
  r.unit = unit;
  r.rate = work / (r.median_ms * 1e-3) / unit_scale;
  r.best_rate = work / (r.min_ms * 1e-3) / unit_scale;
  return r;
}

}  // namespace

Expected<Peaks> measure_peaks(const PeaksSettings& s) {
  if (s.repeats < 1 || s.fma_invocations < 64 || s.fma_iterations < 1 || s.copy_mib < 1 ||
      s.copy_mib > 1024 || s.image_loads < 1)
    return fail(ErrorKind::BadUsage,
                "peaks: repeats >= 1, fma_invocations >= 64, fma_iterations >= 1, copy_mib in "
                "1..1024 and image_loads >= 1");
  auto ctx_or = gpu::Context::create(s.device);
  if (!ctx_or) return ctx_or.error();
  gpu::Context& ctx = **ctx_or;
  Peaks out;
  out.device = ctx.info().name;
  out.driver = ctx.info().driver;
  if (const char* t = std::getenv("LP_NUM_THREADS")) out.lp_num_threads = std::atoi(t);

  auto floor = gpu::measure_floor_pass(ctx, kPeakWidth, kPeakHeight, uint32_t(std::max(s.repeats, 5)));
  if (!floor) return floor.error();
  out.floor_median_ms = floor->median_ms;

  gpu::FrameGraphSettings fs;
  fs.max_output_width = kPeakWidth;
  fs.max_output_height = kPeakHeight;
  fs.frames_in_flight = 1;
  fs.max_passes = 5;
  auto graph_or = gpu::FrameGraph::create(ctx, fs);
  if (!graph_or) return graph_or.error();
  gpu::FrameGraph& graph = **graph_or;
  MRGI_TRY(graph.set_profiling(true));

  const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  const auto img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  const VkDeviceSize copy_bytes = VkDeviceSize(s.copy_mib) << 20;
  const VkDeviceSize result_bytes =
      std::max<VkDeviceSize>(VkDeviceSize(s.fma_invocations), kPeakWidth * kPeakHeight) * 16;
  auto results = graph.create_buffer({"peaks_result", result_bytes}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!results) return results.error();
  auto src = graph.create_buffer({"peaks_copy_src", copy_bytes},
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!src) return src.error();
  auto dst = graph.create_buffer({"peaks_copy_dst", copy_bytes}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!dst) return dst.error();
  {
    // Defined contents: the copy must read real pages, not untouched zero pages.
    std::vector<uint8_t> bytes(static_cast<size_t>(copy_bytes));
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t(i * 131u);
    MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(*src, 0), bytes.data(), copy_bytes));
  }
  gpu::ImageDesc id;
  id.name = "peaks_image";
  id.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  id.size_mode = gpu::SizeMode::Absolute;
  id.width = kPeakWidth;
  id.height = kPeakHeight;
  id.history = true;
  auto image = graph.create_image(id, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  if (!image) return image.error();
  {
    std::vector<float> texels(size_t(kPeakWidth) * kPeakHeight * 4);
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = float(i % 97) * 0.01f;
    MRGI_TRY(graph.upload_image(*image, texels.data(), texels.size() * sizeof(float)));
  }

  auto fma = gpu::load_compute_pipeline(ctx, "perf/peak_fma.comp", {{ssbo}}, 32);
  if (!fma) return fma.error();
  auto copy = gpu::load_compute_pipeline(ctx, "perf/peak_copy.comp", {{ssbo}, {ssbo}}, 16);
  if (!copy) return copy.error();
  auto load = gpu::load_compute_pipeline(ctx, "perf/peak_image_load.comp", {{img}, {ssbo}}, 16);
  if (!load) return load.error();
  auto buffer_floor = gpu::load_compute_pipeline(ctx, "perf/peak_buffer_floor.comp", {{ssbo}, {ssbo}}, 16);
  if (!buffer_floor) return buffer_floor.error();
  auto gather = gpu::load_compute_pipeline(ctx, "perf/peak_buffer_gather.comp", {{ssbo}, {ssbo}}, 16);
  if (!gather) return gather.error();
  const gpu::BufferHandle res = *results, a = *src, b = *dst;
  const gpu::ImageHandle im = *image;

  {
    const gpu::Pipeline& p = **fma;
    struct {
      glm::vec4 factors;
      glm::ivec4 counts;
    } pc{glm::vec4(0.999f, 1e-3f, 0.0f, 0.0f), glm::ivec4(s.fma_iterations, s.fma_invocations, 0, 0)};
    auto ms = time_pass(
        graph, "peak_fma", s.repeats,
        [&](gpu::PassBuilder& pb) {
          pb.write(res, gpu::Access::StorageWrite);
          pb.side_effect();
        },
        [&](VkCommandBuffer cmd, gpu::PassContext& pass) {
          vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
          gpu::DescriptorPush().storage_buffer(0, pass.buffer(res)).push(ctx, cmd, p);
          gpu::dispatch_2d(cmd, p, &pc, sizeof(pc), uint32_t(s.fma_invocations), 1, 64, 1);
        });
    if (!ms) return ms.error();
    const double flops = double(s.fma_invocations) * s.fma_iterations * 32.0 * 2.0;
    out.results.push_back(result("fma", *ms, flops, "GFLOP/s", 1e9));
  }
  // A kernel that reads buffer a and writes buffer b (copy, buffer floor).
  auto time_a_to_b = [&](const char* pass_name, const gpu::Pipeline& p, const glm::ivec4& pc, uint32_t x,
                         uint32_t y, uint32_t local_x, uint32_t local_y) {
    return time_pass(
        graph, pass_name, s.repeats,
        [&](gpu::PassBuilder& pb) {
          pb.read(a, gpu::Access::StorageRead);
          pb.write(b, gpu::Access::StorageWrite);
          pb.side_effect();
        },
        [&](VkCommandBuffer cmd, gpu::PassContext& pass) {
          vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
          gpu::DescriptorPush()
              .storage_buffer(0, pass.buffer(a))
              .storage_buffer(1, pass.buffer(b))
              .push(ctx, cmd, p);
          gpu::dispatch_2d(cmd, p, &pc, sizeof(pc), x, y, local_x, local_y);
        });
  };
  {
    const int elements = int(copy_bytes / 16);
    auto ms = time_a_to_b("peak_copy", **copy, glm::ivec4(elements, 0, 0, 0), uint32_t(elements), 1, 64, 1);
    if (!ms) return ms.error();
    out.results.push_back(result("copy", *ms, 2.0 * double(copy_bytes), "GB/s", 1e9));
  }
  {
    const gpu::Pipeline& p = **load;
    const glm::ivec4 pc(s.image_loads, int(kPeakWidth), int(kPeakHeight), 0);
    auto ms = time_pass(
        graph, "peak_image_load", s.repeats,
        [&](gpu::PassBuilder& pb) {
          pb.read(im, gpu::Access::StorageRead);
          pb.write(res, gpu::Access::StorageWrite);
          pb.side_effect();
        },
        [&](VkCommandBuffer cmd, gpu::PassContext& pass) {
          vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
          gpu::DescriptorPush()
              .storage_image(0, pass.view(im))
              .storage_buffer(1, pass.buffer(res))
              .push(ctx, cmd, p);
          gpu::dispatch_2d(cmd, p, &pc, sizeof(pc), kPeakWidth, kPeakHeight);
        });
    if (!ms) return ms.error();
    const double loads = double(kPeakWidth) * kPeakHeight * s.image_loads;
    out.results.push_back(result("image_load", *ms, loads, "Gload/s", 1e9));
  }
  {
    const glm::ivec4 pc(s.image_loads, int(kPeakWidth), int(kPeakHeight), int(copy_bytes / 16));
    auto ms = time_a_to_b("peak_buffer_gather", **gather, pc, kPeakWidth, kPeakHeight, 8, 8);
    if (!ms) return ms.error();
    const double loads = double(kPeakWidth) * kPeakHeight * s.image_loads;
    out.results.push_back(result("buffer_gather", *ms, loads, "Gload/s", 1e9));
  }
  {
    auto ms = time_a_to_b("peak_buffer_floor", **buffer_floor, glm::ivec4(int(kPeakWidth), int(kPeakHeight), 0, 0),
                          kPeakWidth, kPeakHeight, 8, 8);
    if (!ms) return ms.error();
    // Accesses (one load, one store per pixel), the unit the floor pass spends through images.
    out.results.push_back(result("buffer_floor", *ms, 2.0 * kPeakWidth * kPeakHeight, "Gaccess/s", 1e9));
  }
  return out;
}

std::string peaks_markdown(const Peaks& p) {
  std::ostringstream o;
  o << "# Device peaks (`mrgi peaks`)\n\n"
    << "device: " << p.device << " (" << p.driver << ")";
  if (p.lp_num_threads > 0) o << ", LP_NUM_THREADS=" << p.lp_num_threads;
  o << "\n\nfloor pass (640x480, one RGBA8 load and store per pixel): " << p.floor_median_ms
    << " ms median\n\n"
    << "| kernel | work per run | median ms | rate (median) | rate (fastest run) | median ms "
       "in floor passes |\n|---|---:|---:|---:|---:|---:|\n";
  for (const PeakResult& r : p.results) {
    o << "| " << r.name << " | " << r.work << " | " << r.median_ms << " | " << r.rate << " "
      << r.unit << " | " << r.best_rate << " " << r.unit << " | "
      << (p.floor_median_ms > 0.0 ? r.median_ms / p.floor_median_ms : 0.0) << " |\n";
  }
  o << "\nA pass needing F FLOPs, B streamed bytes and L scattered loads takes at least "
       "max(F / fma, B / copy, L / image_load) (L / buffer_gather where it reads a buffer).\n";
  return o.str();
}

}  // namespace mrgi::perf
