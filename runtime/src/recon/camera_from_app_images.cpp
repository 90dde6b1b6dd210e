// A camera frame given as the app's images (mrgi/vulkan_device.h AppInputImages) into the
// upload buffers every camera reader takes, on the GPU, at the start of the frame's submission:
// the depth image's texels are the u16 words depth_upload() holds, the colour image's 4-byte
// texels the words color_upload() holds (an RGBA image's as they are: the readers ignore the top
// byte), both by a copy; a BGRA image's words are swapped, and the composite's camera words
// written, by shaders/recon/app_color_words.comp. Both are marked as outputs, so the host may
// read them once the frame completes (frame/camera_view.h: the host's view of the frame
// frames_in_flight later).
#include <array>

#include "gpu/context.h"
#include "recon/reconstruction.h"

namespace mrgi::recon {
namespace {


bool is_bgra(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB; }

VkImageAspectFlags depth_aspect(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

// The app's image from its layout to the copy's and back (GENERAL copies as it is). Before: the
// app's earlier writes on this queue, and the wait semaphore's, complete first.
VkImageMemoryBarrier2 copy_barrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout app_layout, bool before) {
  const VkImageLayout copy_layout =
      app_layout == VK_IMAGE_LAYOUT_GENERAL ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  if (before) {
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    b.dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT;
    b.oldLayout = app_layout;
    b.newLayout = copy_layout;
  } else {
    b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    b.srcAccessMask = 0;  // the copy only read it: an execution dependency is enough
    b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.oldLayout = copy_layout;
    b.newLayout = app_layout;
  }
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  return b;
}

}  // namespace

Status Reconstruction::record_app_images(gpu::FrameGraph& graph, gpu::BufferHandle camera_words) {
  const AppInputImages in = *app_images_;
  if (!no_camera_words_.valid())
    return fail(ErrorKind::Internal, "reconstruction: a frame of app images on a runtime made without their colour pass");
  // Without camera words to write the shader's binding still needs a buffer: a 64-byte stand-in.
  const gpu::BufferHandle camera = camera_words.valid() ? camera_words : no_camera_words_;
  words_push_ = glm::ivec4(color_w_ * color_h_, 0, is_bgra(in.color_format) ? 1 : 0, camera_words.valid() ? 1 : 0);
  const gpu::BufferHandle rgba = color_upload_;
  const uint32_t cw = uint32_t(color_w_), ch = uint32_t(color_h_), dw = uint32_t(depth_w_), dh = uint32_t(depth_h_);
  const gpu::Context* ctx = context_;
  graph.add_pass(
      "camera_from_app_images", gpu::PassKind::Transfer,
      [this, rgba](gpu::PassBuilder& b) {
        b.write(depth_upload_, gpu::Access::TransferDst);
        b.write(rgba, gpu::Access::TransferDst);
      },
      [this, in, rgba, cw, ch, dw, dh, ctx](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkImageAspectFlags da = depth_aspect(in.depth_format);
        std::array<VkImageMemoryBarrier2, 2> b{copy_barrier(in.color, VK_IMAGE_ASPECT_COLOR_BIT, in.color_layout, true),
                                               copy_barrier(in.depth, da, in.depth_layout, true)};
        VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        di.imageMemoryBarrierCount = uint32_t(b.size());
        di.pImageMemoryBarriers = b.data();
        ctx->fn().cmd_pipeline_barrier2(cmd, &di);
        VkBufferImageCopy region{};  // rows tightly packed (bufferRowLength 0)
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {cw, ch, 1};
        vkCmdCopyImageToBuffer(cmd, in.color, b[0].newLayout, pass.buffer(rgba), 1, &region);
        region.imageSubresource = {da, 0, 0, 1};
        region.imageExtent = {dw, dh, 1};
        vkCmdCopyImageToBuffer(cmd, in.depth, b[1].newLayout, pass.buffer(depth_upload_), 1, &region);
        b = {copy_barrier(in.color, VK_IMAGE_ASPECT_COLOR_BIT, in.color_layout, false),
             copy_barrier(in.depth, da, in.depth_layout, false)};
        ctx->fn().cmd_pipeline_barrier2(cmd, &di);
      });
  if (words_push_.z != 0 || words_push_.w != 0) {
    graph.add_shader_pass(
        "app_color_words", gpu::PassKind::Compute, *words_pipeline_,
        [this, camera](gpu::ShaderPassBuilder& b) {
          b.bind("ColorWords", color_upload_);
          b.bind("CameraWords", camera);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext&) {
          // app_color_words.comp: 1024 pixels a workgroup.
          gpu::push_and_dispatch(cmd, *words_pipeline_, &words_push_, sizeof(words_push_),
                                 {(uint32_t(words_push_.x) + 1023) / 1024, 1, 1});
        });
  }
  // The host reads both back (the camera frame where nothing virtual shows; the lagged view).
  graph.mark_output(color_upload_);
  graph.mark_output(depth_upload_);
  return graph.add_submit_wait(in.wait, VK_PIPELINE_STAGE_2_COPY_BIT);
}

}  // namespace mrgi::recon
