#include "recon/reconstruction.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "gpu/shaders.h"
#include "shared/mrgi_shared.h"

namespace mrgi::recon {
namespace {

// Shader buffers are read as 32-bit words: round byte sizes up to a multiple of 4.
size_t words_bytes(size_t bytes) { return (bytes + 3) / 4 * 4; }

Expected<gpu::ImageHandle> recon_image(gpu::FrameGraph& graph, const char* name, VkFormat format,
                                          VkImageUsageFlags usage, bool history = false) {
  gpu::ImageDesc d;
  d.name = name;
  d.format = format;
  d.history = history;
  d.size_mode = gpu::SizeMode::OutputRelative;
  d.scale = 1.0f;
  d.follows_render_scale = true;
  return graph.create_image(d, usage);
}

Status check_settings(const ReconstructionSettings& s) {
  const char* where = "recon/reconstruction.cpp ReconstructionSettings";
  if (!(s.max_weight >= 1.0f && s.max_weight <= 255.0f))
    return fail(ErrorKind::BadUsage,
                std::string(where) + ".max_weight must be in [1, 255] (frames, packed in 8 bits)");
  if (!(s.same_surface_relative >= 0.0f && s.same_surface_relative <= 1.0f) ||
      !(s.same_surface_absolute >= 0.0f && s.same_surface_absolute <= 1.0f))
    return fail(ErrorKind::BadUsage,
                std::string(where) + ".same_surface_relative/_absolute must be in [0, 1]");
  if (s.normal_radius < 1 || s.normal_radius > 8)
    return fail(ErrorKind::BadUsage,
                std::string(where) + ".normal_radius must be in [1, 8] pixels");
  return ok_status();
}

}  // namespace

gpu::BufferDesc camera_upload_desc(const std::string& name, size_t bytes) {
  // Host-read too: the host's readers of the camera take a slot's frame frames later.
  gpu::BufferDesc d{name, words_bytes(std::max<size_t>(bytes, 4)), gpu::MemoryUsage::UploadHostRead, true};
  d.texel_format = VK_FORMAT_R32_UINT;
  return d;
}

void rgb8_to_color_words(const uint8_t* rgb, size_t pixels, uint32_t* words) {
  static_assert(std::endian::native == std::endian::little, "colour words are R | G << 8 | B << 16");
  // One 4-byte load a pixel (its RGB and the next pixel's R, masked off); the last pixel
  // byte-wise, so nothing is read past the frame.
  for (size_t i = 0; i + 1 < pixels; ++i) {
    uint32_t v;
    std::memcpy(&v, rgb + 3 * i, 4);
    words[i] = v & 0x00ffffffu;
  }
  if (pixels > 0) {
    const size_t i = pixels - 1;
    words[i] = uint32_t(rgb[3 * i]) | uint32_t(rgb[3 * i + 1]) << 8 | uint32_t(rgb[3 * i + 2]) << 16;
  }
}

Status check_camera_upload(const gpu::FrameGraph& graph, gpu::BufferHandle upload,
                           const std::string& who) {
  if (!upload.valid() || graph.texel_format(upload) != VK_FORMAT_R32_UINT)
    return fail(ErrorKind::BadUsage,
                who + ": camera upload '" + (upload.valid() ? graph.name(upload) : "(none)") +
                    "' lacks the R32_UINT texel view its shaders read (create it with "
                    "recon::camera_upload_desc)");
  return ok_status();
}

Expected<Reconstruction> Reconstruction::create(gpu::Context& context, gpu::FrameGraph& graph,
                                                const Intrinsics& color, const Intrinsics& depth,
                                                const ReconstructionSettings& settings, bool app_images) {
  MRGI_TRY(check_settings(settings));
  Reconstruction r;
  r.settings_ = settings;
  r.context_ = &context;
  r.color_pixels_ = size_t(color.width) * size_t(color.height);
  r.depth_bytes_ = size_t(depth.width) * depth.height * 2;
  r.color_w_ = color.width;
  r.color_h_ = color.height;
  r.depth_w_ = depth.width;
  r.depth_h_ = depth.height;
  // Transfer destination: an app image's copy (AppInputImages) lands in them.
  constexpr VkBufferUsageFlags kUploadUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const gpu::BufferDesc cb = camera_upload_desc("color_upload", color_upload_bytes(r.color_pixels_));
  auto c = graph.create_buffer(cb, kUploadUsage);
  if (!c) return c.error();
  r.color_upload_ = *c;
  const gpu::BufferDesc db = camera_upload_desc("depth_upload", r.depth_bytes_);
  auto d = graph.create_buffer(db, kUploadUsage);
  if (!d) return d.error();
  r.depth_upload_ = *d;
  const gpu::BufferDesc yb = camera_upload_desc("color_yuv_upload", size_t(color.width) * size_t(color.height) * 2);
  auto y = graph.create_buffer(yb, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!y) return y.error();
  r.yuv_upload_ = *y;
  if (app_images) {
    auto none = graph.create_buffer({"camera_words_none", 64}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!none) return none.error();
    r.no_camera_words_ = *none;
    auto wp = gpu::load_compute_pipeline(context, "recon/app_color_words.comp", {});
    if (!wp) return wp.error();
    r.words_pipeline_ = std::move(*wp);
  }

  // Transfer source: tests and debug tools read the reconstruction back.
  const VkImageUsageFlags usage =
      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  auto p = recon_image(graph, "real_position", VK_FORMAT_R32G32B32A32_SFLOAT, usage);
  if (!p) return p.error();
  r.position_ = *p;
  auto n = recon_image(graph, "real_normal", VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  if (!n) return n.error();
  r.normal_ = *n;
  auto a = recon_image(graph, "real_albedo", VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  if (!a) return a.error();
  r.albedo_ = *a;
  auto fd = recon_image(graph, "recon_filtered_depth", VK_FORMAT_R32G32_SFLOAT, usage, true);
  if (!fd) return fd.error();
  r.filtered_depth_ = *fd;
  auto wp = recon_image(graph, "recon_warped_depth", VK_FORMAT_R32_UINT,
                           VK_IMAGE_USAGE_STORAGE_BIT, true);
  if (!wp) return wp.error();
  r.warped_ = *wp;

  // Layouts and push-constant sizes come from the shaders (gpu/reflect.h); the passes bind by name.
  auto pp = gpu::load_compute_pipeline(context, "recon/depth_to_positions.comp", {});
  if (!pp) return pp.error();
  r.positions_pipeline_ = std::move(*pp);
  auto np = gpu::load_compute_pipeline(context, "recon/normals.comp", {});
  if (!np) return np.error();
  r.normals_pipeline_ = std::move(*np);
  auto wpp = gpu::load_compute_pipeline(context, "recon/warp_depth.comp", {});
  if (!wpp) return wpp.error();
  r.warp_pipeline_ = std::move(*wpp);
  auto ypp = gpu::load_compute_pipeline(context, "recon/yuv_to_rgb.comp", {});
  if (!ypp) return ypp.error();
  r.yuv_pipeline_ = std::move(*ypp);
  return r;
}

void Reconstruction::take_input(const InputFrame& frame, const AppInputImages* images) {
  yuv_push_.frame.x = 0;
  app_images_.reset();
  if (images) {
    app_images_ = *images;
  } else if (const std::optional<YuvImage>& yuv = frame.color_yuv) {
    constexpr int kGroupsPerRow = 256;  // the dispatch's row of 4-pixel groups
    yuv_push_.frame = glm::ivec4(yuv->width, yuv->height,
                                 yuv->layout == YuvImage::Layout::Yuyv ? MRGI_YUV_YUYV : MRGI_YUV_NV12, kGroupsPerRow);
    yuv_push_.format = glm::ivec4(yuv->matrix == YuvImage::Matrix::Bt709 ? MRGI_YUV_BT709 : MRGI_YUV_BT601,
                                  yuv->range == YuvImage::Range::Full ? 1 : 0, 0, 0);
  }
  // Same rule as the runtime's frame constants: no pose = the last known one (not moved).
  if (frame.pose) pose_ = frame.pose->matrix();
}

size_t Reconstruction::copy_host_input(const gpu::FrameGraph& graph, const InputFrame& frame) {
  if (app_images_) return 0;
  size_t bytes = depth_bytes_;
  if (const std::optional<YuvImage>& yuv = frame.color_yuv) {
    std::memcpy(graph.mapped(yuv_upload_, graph.slot()), yuv->data.data(), yuv->expected_bytes());
    bytes += yuv->expected_bytes();
  } else {
    rgb8_to_color_words(frame.color.data.data(), color_pixels_, static_cast<uint32_t*>(graph.mapped(color_upload_, graph.slot())));
    bytes += color_pixels_ * kColorWordBytes;
  }
  std::memcpy(graph.mapped(depth_upload_, graph.slot()), frame.depth.data.data(), depth_bytes_);
  return bytes;
}

frame::CameraView Reconstruction::slot_view(const gpu::FrameGraph& graph) const {
  frame::CameraView v;
  v.rgb = static_cast<const uint8_t*>(graph.mapped(color_upload_, graph.slot()));
  v.rgb_stride = int(kColorWordBytes);
  v.color_width = color_w_;
  v.color_height = color_h_;
  v.depth = frame::DepthView{static_cast<const uint16_t*>(graph.mapped(depth_upload_, graph.slot())), depth_w_, depth_h_};
  return v;
}

Status Reconstruction::record_camera_input(gpu::FrameGraph& graph, gpu::BufferHandle camera_words) {
  if (app_images_) return record_app_images(graph, camera_words);
  if (yuv_push_.frame.x == 0) return ok_status();
  graph.add_shader_pass(
      "camera_yuv_to_rgb", gpu::PassKind::Compute, *yuv_pipeline_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("yuv_words", yuv_upload_);
        b.bind("rgb_words", color_upload_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext&) {
        const uint32_t groups = (uint32_t(yuv_push_.frame.x) * uint32_t(yuv_push_.frame.y) + 3) / 4;
        const uint32_t row = uint32_t(yuv_push_.frame.w);
        gpu::dispatch_2d(cmd, *yuv_pipeline_, &yuv_push_, sizeof(yuv_push_), row, (groups + row - 1) / row);
      });
  graph.mark_output(color_upload_);  // the host reads the camera frame from it where nothing virtual shows
  return ok_status();
}

void Reconstruction::record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants) {
  frame_constants_ = frame_constants;
  const VkExtent2D extent = graph.extent(position_);
  // The history is in pixels of the previous internal resolution: after a render-scale change
  // it is dropped rather than warped with the wrong intrinsics.
  const bool warp = settings_.temporal && have_history_ &&
                    extent.width == history_extent_.width &&
                    extent.height == history_extent_.height;
  // Previous camera -> world -> current camera (the DIR paper's T_warp, eq. 12, with poses as
  // camera-to-world), in double so small motions do not vanish in float round-off.
  const glm::dmat4 previous_to_current = glm::inverse(pose_) * previous_pose_;
  previous_to_current_ = glm::mat4(previous_to_current);
  merge_push_.merge = glm::vec4(warp ? 1.0f : 0.0f, settings_.max_weight,
                                settings_.same_surface_relative, settings_.same_surface_absolute);
  merge_push_.options = glm::ivec4(settings_.median ? 1 : 0, 0, 0, 0);
  normal_push_ = glm::ivec4(settings_.normal_radius, 0, 0, 0);
  previous_pose_ = pose_;
  have_history_ = true;
  history_extent_ = extent;

  if (warp) {
    graph.add_shader_pass(
        "recon_warp", gpu::PassKind::Compute, *warp_pipeline_,
        [this](gpu::ShaderPassBuilder& b) {
          b.bind("FrameUbo", frame_constants_);
          b.bind("previous_depth", filtered_depth_);
          b.bind("warped", warped_);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
          const VkExtent2D e = pass.extent(filtered_depth_);
          gpu::dispatch_2d(cmd, *warp_pipeline_, &previous_to_current_,
                           sizeof(previous_to_current_), e.width, e.height);
        });
  }
  graph.add_shader_pass(
      "recon_positions", gpu::PassKind::Compute, *positions_pipeline_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("color_words", color_upload_);
        b.bind("depth_words", depth_upload_);
        b.bind("real_position", position_);
        b.bind("real_albedo", albedo_);
        b.bind("warped", warped_);
        b.bind("filtered_depth", filtered_depth_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(position_);
        gpu::dispatch_2d(cmd, *positions_pipeline_, &merge_push_, sizeof(merge_push_), e.width,
                         e.height);
      });
  graph.add_shader_pass(
      "recon_normals", gpu::PassKind::Compute, *normals_pipeline_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", frame_constants_);
        b.bind("real_position", position_);
        b.bind("real_normal", normal_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(normal_);
        gpu::dispatch_2d(cmd, *normals_pipeline_, &normal_push_, sizeof(normal_push_), e.width,
                         e.height);
      });
}

}  // namespace mrgi::recon
