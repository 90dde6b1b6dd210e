// The test apps' images (mrgi/vulkan_device.h AppInputImages, AppOutputImage): an image of the
// app's with a host-visible buffer beside it, the app's own submissions that fill it from host
// bytes and read it back.
#pragma once
#include <cstdint>
#include <cstring>

#include "app_vulkan.h"

namespace mrgi::test {

// One image of the app's with a host-visible buffer to read it back into.
struct AppImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkBuffer readback = VK_NULL_HANDLE;
  VkDeviceMemory readback_memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkSemaphore written = VK_NULL_HANDLE;  // signalled by the runtime
};

inline uint32_t memory_type(VkPhysicalDevice pd, uint32_t bits, VkMemoryPropertyFlags want) {
  VkPhysicalDeviceMemoryProperties mp{};
  vkGetPhysicalDeviceMemoryProperties(pd, &mp);
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
  return ~0u;
}

// `format`'s texels are 4 bytes (RGBA8 / BGRA8) or 2 (R16 / D16); usable as a copy's source and
// destination and sampled (so SHADER_READ_ONLY_OPTIMAL is a layout it may be in).
inline bool make_image(AppVulkan& app, uint32_t w, uint32_t h, VkFormat format, AppImage& out) {
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {w, h, 1};
  ici.mipLevels = ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  if (vkCreateImage(app.device, &ici, nullptr, &out.image) != VK_SUCCESS) return false;
  VkMemoryRequirements mr{};
  vkGetImageMemoryRequirements(app.device, out.image, &mr);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = mr.size;
  mai.memoryTypeIndex = memory_type(app.physical, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (vkAllocateMemory(app.device, &mai, nullptr, &out.memory) != VK_SUCCESS) return false;
  vkBindImageMemory(app.device, out.image, out.memory, 0);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = VkDeviceSize(w) * h * 4;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;  // read back, or fill from
  if (vkCreateBuffer(app.device, &bci, nullptr, &out.readback) != VK_SUCCESS) return false;
  vkGetBufferMemoryRequirements(app.device, out.readback, &mr);
  mai.allocationSize = mr.size;
  mai.memoryTypeIndex = memory_type(app.physical, mr.memoryTypeBits,
                                    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (vkAllocateMemory(app.device, &mai, nullptr, &out.readback_memory) != VK_SUCCESS) return false;
  vkBindBufferMemory(app.device, out.readback, out.readback_memory, 0);
  vkMapMemory(app.device, out.readback_memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  return vkCreateSemaphore(app.device, &sci, nullptr, &out.written) == VK_SUCCESS;
}

inline void destroy_image(AppVulkan& app, AppImage& i) {
  vkDestroySemaphore(app.device, i.written, nullptr);
  vkDestroyBuffer(app.device, i.readback, nullptr);
  vkFreeMemory(app.device, i.readback_memory, nullptr);
  vkDestroyImage(app.device, i.image, nullptr);
  vkFreeMemory(app.device, i.memory, nullptr);
}

// One submission of the app's, recorded by `record`, waiting for `wait` (at the transfer stage)
// and signalling `signal` (each may be null); waited for on a fence.
template <typename Record>
bool submit_once(AppVulkan& app, Record record, VkSemaphore wait, VkSemaphore signal) {
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = app.family;
  VkCommandPool pool = VK_NULL_HANDLE;
  vkCreateCommandPool(app.device, &pci, nullptr, &pool);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vkAllocateCommandBuffers(app.device, &cai, &cmd);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &bi);
  record(cmd);
  vkEndCommandBuffer(cmd);
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = wait ? 1 : 0;
  si.pWaitSemaphores = &wait;
  si.pWaitDstStageMask = &stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  si.signalSemaphoreCount = signal ? 1 : 0;
  si.pSignalSemaphores = &signal;
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  vkCreateFence(app.device, &fci, nullptr, &fence);
  bool ok = vkQueueSubmit(app.queue, 1, &si, fence) == VK_SUCCESS &&
            vkWaitForFences(app.device, 1, &fence, VK_TRUE, 30'000'000'000ull) == VK_SUCCESS;
  vkDestroyFence(app.device, fence, nullptr);
  vkDestroyCommandPool(app.device, pool, nullptr);
  return ok;
}

// The app's own submission: waits for the runtime's semaphore, copies the image (left by the
// runtime in TRANSFER_SRC_OPTIMAL) into its readback buffer.
inline bool read_back(AppVulkan& app, const AppImage& img, uint32_t w, uint32_t h) {
  auto record = [&](VkCommandBuffer cmd) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cmd, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img.readback, 1, &region);
  };
  return submit_once(app, record, img.written, VK_NULL_HANDLE);
}

// The app's submission that fills the image from `bytes` (through its buffer) and leaves it in
// `layout`, signalling `img.written` where `signal` (what the runtime waits for:
// AppInputImages::wait); done when this returns, so the buffer may be written again at once.
inline bool fill(AppVulkan& app, const AppImage& img, uint32_t w, uint32_t h, const void* bytes, size_t size,
                 VkImageAspectFlags aspect, VkImageLayout layout, bool signal) {
  std::memcpy(img.mapped, bytes, size);
  auto record = [&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = 0;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img.image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {w, h, 1};
    vkCmdCopyBufferToImage(cmd, img.readback, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = layout;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
  };
  return submit_once(app, record, VK_NULL_HANDLE, signal ? img.written : VK_NULL_HANDLE);
}

}  // namespace mrgi::test
