// Reconstruction (docs/DESIGN.md "One frame, as data"): the real G-buffer from the RGB-D stream, with
// the DIR paper's temporal depth filter (section 4.2, eq. 11-14).
//   upload          colour (sRGB8, one word a pixel) and depth (u16) copied into this frame
//                   slot's upload buffers by the host, or for a frame given as the app's images
//                   by the GPU (camera_from_app_images, app_color_words); the pose change since the
//                   previous frame is computed here (CPU, double)
//   recon_warp      the previous frame's filtered depth + weight (history image) forward-
//                   projected into this view as its grid mesh (each pixel a triangle covers gets
//                   the interpolated depth; atomicMin between surfaces); skipped on the first frame,
//                   after a render-scale change, or when settings.temporal is off
//   recon_positions raw depth (3x3 median) merged with the warped depth (weighted running
//                   average; new depth alone where the two are different surfaces) -> view
//                   space -> world (frame pose); albedo from the camera colour (DIR
//                   approximation); writes the filtered depth + weight for the next frame
//   recon_normals   normals from neighbouring positions (DIR eq. in section 4.2) as central
//                   differences over +-normal_radius pixels, one-pixel fallbacks at holes and
//                   depth edges, facing the camera
// Output images (internal resolution = output x render scale): real_position (RGBA32F: xyz
// world, w depth in metres; all 0 = invalid), real_normal (RGBA16F: xyz, w 1 valid),
// real_albedo (RGBA16F: linear rgb, w 1 valid). Invalid stays invalid in every later step.
// A frame without a pose is treated as not moved (the runtime keeps the previous pose for it).
#pragma once
#include "frame/camera_view.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/frame.h"
#include "mrgi/vulkan_device.h"

#include <cstddef>
#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

namespace mrgi::recon {

struct ReconstructionSettings {
  bool temporal = true;             // warp-and-merge with the previous frames (DIR 4.2)
  float max_weight = 16.0f;         // frames: cap of the running average's weight, [1, 255]
  // Two depths are one surface when |z_new - z_warped| <= max(relative x z_new, absolute m):
  // a few sigma of Kinect noise plus disparity steps at 1-3 m (~1-2 cm at 2 m).
  float same_surface_relative = 0.03f;
  float same_surface_absolute = 0.02f;  // metres
  bool median = true;               // 3x3 median of the raw depth before the merge
  int normal_radius = 2;            // pixels: central-difference half-width for normals, [1, 8]
};

// How a camera upload buffer (colour words or u16 depth packed into uint words, host-written each
// frame) is created, as every pass that reads one expects it: one copy per frame slot, rounded
// to whole words, with the R32_UINT texel view shaders/common/upload_gather.glsl reads.
gpu::BufferDesc camera_upload_desc(const std::string& name, size_t bytes);
// The colour upload's layout (common/upload_gather.glsl color_words): one 32-bit word a pixel,
// R | G << 8 | B << 16, the top byte ignored by every reader. A word a pixel because every
// buffer read is a per-lane gather on lavapipe (three bytes a pixel took two reads) and because
// an app's RGBA image then copies into it as it is (recon/camera_from_app_images.cpp).
inline constexpr size_t kColorWordBytes = 4;
// The upload's size for `pixels` pixels: whole groups of 16 pixels (the app colour pass's step,
// shaders/recon/app_color_words.comp).
inline size_t color_upload_bytes(size_t pixels) { return (pixels + 15) / 16 * 16 * kColorWordBytes; }
// `pixels` sRGB8 pixels (3 bytes each, tightly packed) as colour words (top byte 0).
void rgb8_to_color_words(const uint8_t* rgb, size_t pixels, uint32_t* words);
// BadUsage naming `who` unless `upload` was created that way (has the texel view).
Status check_camera_upload(const gpu::FrameGraph& graph, gpu::BufferHandle upload,
                           const std::string& who);

class Reconstruction {
 public:
  // Buffers sized for the colour and depth images; images allocated at the output size.
  // `app_images`: frames may come as the app's images (the pass that finishes their colour).
  static Expected<Reconstruction> create(gpu::Context& context, gpu::FrameGraph& graph,
                                         const Intrinsics& color, const Intrinsics& depth,
                                         const ReconstructionSettings& settings = {}, bool app_images = false);
  // The frame's input, in two steps around its recording (between FrameGraph::begin_frame and
  // submit; sizes and formats checked by the caller). take_input() before any stage: the pose,
  // and the form the colour comes in (RGB8, Y'CbCr for record_camera_input to convert, or the
  // app's images for it to copy: `images`, null for host memory). copy_host_input() after the
  // stages: the host's copies into the current slot's upload buffers (none for app images),
  // after any host reader of the slot's earlier frame (slot_view) is done. Returns the bytes
  // copied (FrameStats::host_copy_bytes).
  void take_input(const InputFrame& frame, const AppInputImages* images);
  size_t copy_host_input(const gpu::FrameGraph& graph, const InputFrame& frame);
  // The images the current slot's upload buffers hold, colour words and u16 depth (the frame
  // recorded in this slot before, once it completed: frame/camera_view.h); index, timestamp and
  // pose are the caller's to fill.
  frame::CameraView slot_view(const gpu::FrameGraph& graph) const;
  // Adds the passes that bring this frame's colour into color_upload()'s words on the GPU,
  // before any pass reads them, kept for the host's reads too (the camera frame where nothing
  // virtual shows, slot_view): camera_yuv_to_rgb for a Y'CbCr colour
  // (shaders/recon/yuv_to_rgb.comp); for the app's images camera_from_app_images (their copy
  // into depth_upload() and color_upload()) and, for a BGRA image or where `camera_words` is
  // valid, app_color_words (shaders/recon/app_color_words.comp). `camera_words`, where valid (the
  // composite's RGBA8 output words, at the colour's size), takes the app's colour as the
  // composite's camera words (alpha 0) on the way. Nothing for an RGB8 frame in host memory. Every frame, whether or not the reconstruction runs.
  Status record_camera_input(gpu::FrameGraph& graph, gpu::BufferHandle camera_words = {});
  // Adds recon_warp (when there is a history), recon_positions and recon_normals.
  void record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants);
  // A frame on which the reconstruction is not recorded (nothing virtual in view): the temporal
  // history is dropped, so the next recorded frame starts from its own depth instead of
  // merging a history that stopped frames ago.
  void skip_frame() { have_history_ = false; }

  gpu::BufferHandle color_upload() const { return color_upload_; }
  gpu::BufferHandle depth_upload() const { return depth_upload_; }
  gpu::ImageHandle position() const { return position_; }
  gpu::ImageHandle normal() const { return normal_; }
  gpu::ImageHandle albedo() const { return albedo_; }
  // RG32F history: filtered depth (metres, 0 = invalid) and its weight (frames).
  gpu::ImageHandle filtered_depth() const { return filtered_depth_; }

 private:
  gpu::BufferHandle color_upload_, depth_upload_, frame_constants_;
  gpu::ImageHandle position_, normal_, albedo_, filtered_depth_, warped_;
  gpu::PipelineHandle warp_pipeline_, positions_pipeline_, normals_pipeline_;
  size_t color_pixels_ = 0, depth_bytes_ = 0;
  int color_w_ = 0, color_h_ = 0, depth_w_ = 0, depth_h_ = 0;
  // The app's images for this frame (take_input), the colour words pass (made only for a
  // runtime that takes app images) and its stand-in for no camera words.
  std::optional<AppInputImages> app_images_;
  gpu::BufferHandle no_camera_words_;
  gpu::PipelineHandle words_pipeline_;
  glm::ivec4 words_push_{0};
  Status record_app_images(gpu::FrameGraph& graph, gpu::BufferHandle camera_words);
  const gpu::Context* context_ = nullptr;  // for the app images' barriers (synchronization2 entry points)
  // Y'CbCr colour: its upload (sized for YUYV, the larger layout), the conversion, and this
  // frame's layout and format (yuv_to_rgb.comp ConvertConstants; frame.x 0: an RGB8 frame).
  gpu::BufferHandle yuv_upload_;
  gpu::PipelineHandle yuv_pipeline_;
  struct YuvPush {
    glm::ivec4 frame{0};
    glm::ivec4 format{0};
  } yuv_push_;
  ReconstructionSettings settings_;
  // Poses (camera-to-world) of this frame and the last recorded one; the history is usable
  // when a frame was recorded before at the same internal extent.
  glm::dmat4 pose_{1.0}, previous_pose_{1.0};
  bool have_history_ = false;
  VkExtent2D history_extent_{0, 0};
  // Push constants, filled in record() (kept here so the callbacks need no allocation).
  glm::mat4 previous_to_current_{1.0f};
  struct MergePush {
    glm::vec4 merge;
    glm::ivec4 options;
  } merge_push_{};
  glm::ivec4 normal_push_{2, 0, 0, 0};
};

}  // namespace mrgi::recon
