#include "technique/ssrt/depth_filter_gpu.h"
#include "recon/reconstruction.h"

#include <algorithm>
#include <cmath>
#include <string>


namespace mrgi::ssrt {
namespace {

constexpr int kMaxTapsPerSide = 5;     // the median networks hold 25 values
// Tap reach, pixels: no shader limit (taps are fetched directly), but a window beyond it mixes
// surfaces that have nothing to do with each other at the paper's 640 x 480.
constexpr int kMaxReach = 16;
// Tangent radius of the G-buffer's normals, pixels (recon's default normal_radius).
constexpr uint32_t kNormalRadiusPx = 2;

const char* kWhere = "technique/ssrt/depth_filter_gpu.cpp DepthFilterSettings.";

// The sub-sampled window of a paper k exactly as the CPU reference walks it: offsets -r..r by
// `stride` (r = side / 2), i.e. 2 * (r / stride) + 1 taps per side reaching (r / stride) * stride.
struct TapWindow {
  int reach = 0, stride = 1, taps = 1;
};
TapWindow tap_window(uint32_t k, uint32_t median_taps) {
  const uint32_t side = window_side(k);
  const int r = int(side / 2);
  const int stride = int(window_stride(side, median_taps));
  const int half = r / stride;
  return TapWindow{half * stride, stride, 2 * half + 1};
}

Status check_gpu_window(const char* field, const TapWindow& w) {
  if (w.taps > kMaxTapsPerSide)
    return fail(ErrorKind::BadUsage,
                std::string(kWhere) + field + ": the GPU filter reads at most " +
                    std::to_string(kMaxTapsPerSide) + " sub-sampled taps per side, this window has " +
                    std::to_string(w.taps) + " (use a window that is <= median_taps or larger)");
  if (w.reach > kMaxReach)
    return fail(ErrorKind::BadUsage, std::string(kWhere) + field +
                                         ": the GPU filter's taps reach at most " +
                                         std::to_string(kMaxReach) + " pixels, this window " +
                                         std::to_string(w.reach));
  return ok_status();
}

Expected<gpu::ImageHandle> internal_image(gpu::FrameGraph& graph, const char* name,
                                          VkFormat format) {
  gpu::ImageDesc d;
  d.name = name;
  d.format = format;
  d.size_mode = gpu::SizeMode::OutputRelative;
  d.scale = 1.0f;
  d.follows_render_scale = true;
  // Sampled: the transfer reads the G-buffer through samplers; transfer source: tests and
  // debug tools read every stage back.
  return graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                   VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
}

}  // namespace

Expected<DepthFilterGpu> DepthFilterGpu::create(gpu::Context& ctx, gpu::FrameGraph& graph,
                                                const frame::FrameResources& shared,
                                                const DepthFilterSettings& settings) {
  MRGI_TRY(validate(settings));
  const TapWindow merge = tap_window(settings.merge_window, settings.median_taps);
  const TapWindow bilateral = tap_window(settings.bilateral_window, settings.median_taps);
  MRGI_TRY(check_gpu_window("merge_window", merge));
  MRGI_TRY(check_gpu_window("bilateral_window", bilateral));
  if (window_side(settings.final_window) > 5)
    return fail(ErrorKind::BadUsage, std::string(kWhere) +
                                         "final_window: the GPU filter's D''' window is at most "
                                         "5 x 5 pixels (final_window <= 5)");
  if (!shared.frame_constants.valid() || !shared.color_upload.valid() ||
      !shared.depth_upload.valid())
    return fail(ErrorKind::BadUsage,
                "technique/ssrt/depth_filter_gpu.cpp: frame::FrameResources needs frame_constants, "
                "color_upload and depth_upload");
  MRGI_TRY(recon::check_camera_upload(graph, shared.color_upload, "ssrt depth filter"));
  MRGI_TRY(recon::check_camera_upload(graph, shared.depth_upload, "ssrt depth filter"));

  DepthFilterGpu f;
  f.graph_ = &graph;
  f.settings_ = settings;
  f.frame_constants_ = shared.frame_constants;
  f.color_upload_ = shared.color_upload;
  f.depth_upload_ = shared.depth_upload;
  const struct {
    gpu::ImageHandle* handle;
    const char* name;
    VkFormat format;
  } images[] = {
      {&f.input_, "ssrt_depth_input", VK_FORMAT_R32G32_SFLOAT},
      {&f.merged_, "ssrt_depth_merged", VK_FORMAT_R32_SFLOAT},
      {&f.merged_intensity_, "ssrt_depth_merged_intensity", VK_FORMAT_R32G32_SFLOAT},
      {&f.bilateral_, "ssrt_depth_bilateral", VK_FORMAT_R32_SFLOAT},
      {&f.final_, "ssrt_depth_final", VK_FORMAT_R32_SFLOAT},
      {&f.position_, "ssrt_position", VK_FORMAT_R32G32B32A32_SFLOAT},
      {&f.normal_, "ssrt_normal", VK_FORMAT_R16G16B16A16_SFLOAT},
  };
  for (const auto& im : images) {
    auto h = internal_image(graph, im.name, im.format);
    if (!h) return h.error();
    *im.handle = *h;
  }
  gpu::ImageDesc nv;
  nv.name = "ssrt_no_volume";
  nv.format = VK_FORMAT_R32_SFLOAT;
  nv.size_mode = gpu::SizeMode::Absolute;
  nv.width = nv.height = 1;
  auto no_volume =
      graph.create_image(nv, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  if (!no_volume) return no_volume.error();
  f.no_volume_ = *no_volume;
  const float zero = 0.0f;  // defined contents and the GENERAL layout (never read by the shader)
  MRGI_TRY(graph.upload_image(f.no_volume_, &zero, sizeof(zero)));

  // Layouts and push-constant sizes come from the shaders (gpu/reflect.h); the passes bind by name.
  auto p = gpu::load_compute_pipeline(ctx, "ssrt/depth_input.comp", {});
  if (!p) return p.error();
  f.input_pipe_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/depth_merge.comp", {});
  if (!p) return p.error();
  f.merge_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/depth_bilateral.comp", {});
  if (!p) return p.error();
  f.bilateral_pipe_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/depth_final.comp", {});
  if (!p) return p.error();
  f.final_pipe_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/depth_gbuffer.comp", {});
  if (!p) return p.error();
  f.gbuffer_ = std::move(*p);

  f.merge_push_.window = glm::ivec4(merge.reach, merge.stride, merge.taps, 0);
  f.merge_push_.thresholds =
      glm::vec4(settings.intensity_threshold, settings.depth_threshold_m, 0.0f, 0.0f);
  f.bilateral_push_.window = glm::ivec4(bilateral.reach, bilateral.stride, bilateral.taps, 0);
  f.bilateral_push_.thresholds = f.merge_push_.thresholds;
  f.final_push_ = glm::ivec4(int(window_side(settings.final_window) / 2), 0, 0, 0);
  return f;
}

Status DepthFilterGpu::record(gpu::ImageHandle depth_volume, bool final_pass,
                              std::vector<std::string>& skipped, uint32_t texel_pixels) {
  if (!graph_)
    return fail(ErrorKind::BadUsage, "technique/ssrt/depth_filter_gpu.cpp: record() before create()");
  if (texel_pixels < 1 || texel_pixels > 64)
    return fail(ErrorKind::BadUsage, "technique/ssrt/depth_filter_gpu.cpp record: texel_pixels " +
                                         std::to_string(texel_pixels) + " must be in 1..64");
  {
    // Windows at this texel size (create() checked the largest, texel_pixels 1).
    auto scaled = [&](uint32_t k) {
      return std::max(1u, uint32_t(std::lround(double(k) / double(texel_pixels))));
    };
    const TapWindow merge = tap_window(scaled(settings_.merge_window), settings_.median_taps);
    const TapWindow bilateral = tap_window(scaled(settings_.bilateral_window), settings_.median_taps);
    merge_push_.window = glm::ivec4(merge.reach, merge.stride, merge.taps, 0);
    bilateral_push_.window = glm::ivec4(bilateral.reach, bilateral.stride, bilateral.taps, 0);
    final_push_ = glm::ivec4(int(window_side(scaled(settings_.final_window)) / 2), 0, 0, 0);
    gbuffer_push_ = glm::ivec4(int(scaled(kNormalRadiusPx)), 0, 0, 0);
  }
  if (depth_volume.valid()) {
    const gpu::GpuImage& v = graph_->gpu_image(depth_volume);
    const VkExtent2D need = graph_->allocated_extent(merged_);
    if (v.format != VK_FORMAT_R32_SFLOAT || v.extent.width < need.width ||
        v.extent.height < need.height)
      return fail(ErrorKind::BadUsage,
                  "technique/ssrt/depth_filter_gpu.cpp record: depth_volume '" +
                      graph_->name(depth_volume) +
                      "' must be R32F and at least the internal resolution (" +
                      std::to_string(need.width) + "x" + std::to_string(need.height) + ")");
  }
  volume_ = depth_volume.valid() ? depth_volume : no_volume_;
  merge_push_.window.w = depth_volume.valid() ? 1 : 0;
  gpu::FrameGraph& graph = *graph_;

  graph.add_shader_pass(
      "ssrt_depth_input", gpu::PassKind::Compute, *input_pipe_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("color_words", color_upload_);
        b.bind("depth_words", depth_upload_);
        b.bind("depth_volume", volume_);
        b.bind("depth_input", input_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(input_);
        gpu::dispatch_2d(cmd, *input_pipe_, &merge_push_, sizeof(merge_push_), e.width, e.height);
      });

  graph.add_shader_pass(
      "ssrt_depth_merge", gpu::PassKind::Compute, *merge_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("depth_input", input_);
        b.bind("depth_volume", volume_);
        b.bind("merged", merged_);
        b.bind("merged_intensity", merged_intensity_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(merged_);
        gpu::dispatch_2d(cmd, *merge_, &merge_push_, sizeof(merge_push_), e.width, e.height);
      });

  graph.add_shader_pass(
      "ssrt_depth_bilateral", gpu::PassKind::Compute, *bilateral_pipe_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("merged_intensity", merged_intensity_);
        b.bind("bilateral", bilateral_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(bilateral_);
        gpu::dispatch_2d(cmd, *bilateral_pipe_, &bilateral_push_, sizeof(bilateral_push_),
                         e.width, e.height);
      });

  if (final_pass) {
    graph.add_shader_pass(
        "ssrt_depth_final", gpu::PassKind::Compute, *final_pipe_,
        [this](gpu::ShaderPassBuilder& b) {
          b.bind("FrameUbo", frame_constants_);
          b.bind("bilateral", bilateral_);
          b.bind("final_depth", final_);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
          const VkExtent2D e = pass.extent(final_);
          gpu::dispatch_2d(cmd, *final_pipe_, &final_push_, sizeof(final_push_), e.width,
                           e.height);
        });
    gbuffer_source_ = final_;
  } else {
    skipped.push_back("ssrt_depth_final: final_pass off at this level (D'' feeds the G-buffer)");
    gbuffer_source_ = bilateral_;
  }

  graph.add_shader_pass(
      "ssrt_gbuffer", gpu::PassKind::Compute, *gbuffer_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("depth", gbuffer_source_);
        b.bind("position", position_);
        b.bind("normal", normal_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(position_);
        gpu::dispatch_2d(cmd, *gbuffer_, &gbuffer_push_, sizeof(gbuffer_push_), e.width, e.height);
      });
  return ok_status();
}

}  // namespace mrgi::ssrt
