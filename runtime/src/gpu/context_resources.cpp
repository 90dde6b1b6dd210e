// Context's memory, images, buffers and one-off uploads (gpu/context.h); device and instance
// set-up, device listing and validation messages are in context.cpp.
#include <cstring>

#include "gpu/context.h"
#include "gpu/vk_check.h"

namespace mrgi::gpu {
namespace {

constexpr uint64_t kUploadTimeoutNs = 30ull * 1000 * 1000 * 1000;  // a one-off upload's fence wait

}  // namespace

Expected<VkDeviceMemory> Context::allocate(const VkMemoryRequirements& req, MemoryUsage usage, bool* coherent) {
  VkMemoryPropertyFlags need = 0, prefer = 0;
  switch (usage) {
    case MemoryUsage::DeviceLocal: need = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT; break;
    case MemoryUsage::Upload:
      need = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      break;
    case MemoryUsage::UploadHostRead:
      need = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      prefer = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
    case MemoryUsage::Readback:
      need = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
      prefer = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
  }
  int best = -1;
  for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
    if (!(req.memoryTypeBits & (1u << i))) continue;
    const VkMemoryPropertyFlags f = memory_properties_.memoryTypes[i].propertyFlags;
    if ((f & need) != need) continue;
    if (best < 0 || ((f & prefer) == prefer &&
                     (memory_properties_.memoryTypes[best].propertyFlags & prefer) != prefer))
      best = int(i);
  }
  if (best < 0)
    return fail(ErrorKind::Device, "no memory type with the properties a resource needs (type bits " +
                                       std::to_string(req.memoryTypeBits) + ")");
  if (coherent)
    *coherent = (memory_properties_.memoryTypes[best].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = uint32_t(best);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VK_CHECK(vkAllocateMemory(device_, &ai, nullptr, &memory));
  // DeviceSettings::poison_memory: 0xff bytes (NaN as floats, 0xffffffff as indices).
  if (poison_memory_ && (memory_properties_.memoryTypes[best].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
    void* p = nullptr;
    if (vkMapMemory(device_, memory, 0, VK_WHOLE_SIZE, 0, &p) == VK_SUCCESS) {
      std::memset(p, 0xff, size_t(req.size));
      vkUnmapMemory(device_, memory);
    }
  }
  allocated_bytes_ += req.size;
  ++allocation_count_;
  return memory;
}

Expected<GpuBuffer> Context::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage memory,
                                           const std::string& name) {
  if (size == 0) return fail(ErrorKind::BadUsage, "buffer '" + name + "': size must be > 0");
  GpuBuffer b;
  b.size = size;
  b.usage = usage;
  b.memory_usage = memory;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device_, &bci, nullptr, &b.buffer));
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  auto mem = allocate(req, memory, &b.coherent);
  if (!mem) {
    vkDestroyBuffer(device_, b.buffer, nullptr);
    return mem.error();
  }
  b.memory = *mem;
  b.allocated = req.size;
  const VkResult bind = vkBindBufferMemory(device_, b.buffer, b.memory, 0);
  VkResult map = VK_SUCCESS;
  if (bind == VK_SUCCESS && memory != MemoryUsage::DeviceLocal)
    map = vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped);
  if (bind != VK_SUCCESS || map != VK_SUCCESS) {
    destroy(b);
    return vk_error(bind != VK_SUCCESS ? bind : map, "vkBindBufferMemory/vkMapMemory", __FILE__, __LINE__);
  }
  set_name(VK_OBJECT_TYPE_BUFFER, uint64_t(b.buffer), name);
  return b;
}

Expected<GpuImage> Context::create_image(const ImageCreateDesc& desc) {
  if (desc.width == 0 || desc.height == 0 || desc.depth == 0 || desc.mip_levels == 0 || desc.layers == 0)
    return fail(ErrorKind::BadUsage, "image '" + desc.name + "': width, height, depth, mip_levels and layers must be > 0");
  if (desc.usage == 0) return fail(ErrorKind::BadUsage, "image '" + desc.name + "': no usage flags");
  const bool is_3d = desc.depth > 1;
  if (is_3d && desc.layers != 1)
    return fail(ErrorKind::BadUsage, "image '" + desc.name + "': a 3D image (depth > 1) has one layer");
  const uint32_t max_dim = is_3d ? properties_.limits.maxImageDimension3D : properties_.limits.maxImageDimension2D;
  if (desc.width > max_dim || desc.height > max_dim || desc.depth > max_dim)
    return fail(ErrorKind::BadUsage, "image '" + desc.name + "': " + std::to_string(desc.width) + "x" +
                                         std::to_string(desc.height) + "x" + std::to_string(desc.depth) +
                                         " exceeds the device limit " + std::to_string(max_dim));
  const uint32_t largest = std::max({desc.width, desc.height, desc.depth});
  uint32_t full_chain = 1;
  while ((largest >> full_chain) > 0) ++full_chain;
  if (desc.mip_levels > full_chain)
    return fail(ErrorKind::BadUsage, "image '" + desc.name + "': " + std::to_string(desc.mip_levels) +
                                         " mip levels, more than the " + std::to_string(full_chain) +
                                         " its size has");
  VkImageFormatProperties fp{};
  const VkResult support = vkGetPhysicalDeviceImageFormatProperties(
      physical_, desc.format, is_3d ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL, desc.usage, 0, &fp);
  if (support != VK_SUCCESS)
    return fail(ErrorKind::Device, "image '" + desc.name + "': format " + std::to_string(int(desc.format)) +
                                       " with usage 0x" + std::to_string(desc.usage) +
                                       " is not supported by the device (" + vk_result_name(support) + ")");
  GpuImage img;
  img.format = desc.format;
  img.extent = {desc.width, desc.height};
  img.depth = desc.depth;
  img.mip_levels = desc.mip_levels;
  img.layers = desc.layers;
  img.aspect = aspect_of(desc.format);
  img.usage = desc.usage;
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = is_3d ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
  ici.format = desc.format;
  ici.extent = {desc.width, desc.height, desc.depth};
  ici.mipLevels = desc.mip_levels;
  ici.arrayLayers = desc.layers;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = desc.usage;
  ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(device_, &ici, nullptr, &img.image));
  VkMemoryRequirements req{};
  vkGetImageMemoryRequirements(device_, img.image, &req);
  auto mem = allocate(req, MemoryUsage::DeviceLocal, nullptr);
  if (!mem) {
    vkDestroyImage(device_, img.image, nullptr);
    return mem.error();
  }
  img.memory = *mem;
  img.allocated = req.size;
  const VkResult bind = vkBindImageMemory(device_, img.image, img.memory, 0);
  if (bind != VK_SUCCESS) {
    destroy(img);
    return vk_error(bind, "vkBindImageMemory", __FILE__, __LINE__);
  }
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img.image;
  vci.viewType = is_3d                                 ? VK_IMAGE_VIEW_TYPE_3D
                 : desc.layers > 1 || desc.array_view ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                      : VK_IMAGE_VIEW_TYPE_2D;
  vci.format = desc.format;
  vci.subresourceRange = {img.aspect, 0, desc.mip_levels, 0, desc.layers};
  const VkResult view = vkCreateImageView(device_, &vci, nullptr, &img.view);
  if (view != VK_SUCCESS) {
    destroy(img);
    return vk_error(view, "vkCreateImageView", __FILE__, __LINE__);
  }
  for (uint32_t m = 0; m < desc.mip_levels && desc.mip_levels > 1; ++m) {
    vci.subresourceRange = {img.aspect, m, 1, 0, desc.layers};
    VkImageView v = VK_NULL_HANDLE;
    const VkResult mv = vkCreateImageView(device_, &vci, nullptr, &v);
    if (mv != VK_SUCCESS) {
      destroy(img);
      return vk_error(mv, "vkCreateImageView (mip level)", __FILE__, __LINE__);
    }
    img.mip_views.push_back(v);
    set_name(VK_OBJECT_TYPE_IMAGE_VIEW, uint64_t(v), desc.name + " mip " + std::to_string(m));
  }
  set_name(VK_OBJECT_TYPE_IMAGE, uint64_t(img.image), desc.name);
  set_name(VK_OBJECT_TYPE_IMAGE_VIEW, uint64_t(img.view), desc.name);
  return img;
}

void Context::destroy(GpuBuffer& b) {
  if (b.texel_view) vkDestroyBufferView(device_, b.texel_view, nullptr);
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) {
    if (b.mapped) vkUnmapMemory(device_, b.memory);
    vkFreeMemory(device_, b.memory, nullptr);
    allocated_bytes_ -= b.allocated;
    --allocation_count_;
  }
  b = GpuBuffer{};
}

void Context::destroy(GpuImage& img) {
  for (VkImageView v : img.mip_views) vkDestroyImageView(device_, v, nullptr);
  if (img.view) vkDestroyImageView(device_, img.view, nullptr);
  if (img.image) vkDestroyImage(device_, img.image, nullptr);
  if (img.memory) {
    vkFreeMemory(device_, img.memory, nullptr);
    allocated_bytes_ -= img.allocated;
    --allocation_count_;
  }
  img = GpuImage{};
}

Status Context::invalidate(const GpuBuffer& b) {
  if (b.coherent || !b.memory) return ok_status();
  VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = b.memory;
  range.size = VK_WHOLE_SIZE;
  VK_CHECK(vkInvalidateMappedMemoryRanges(device_, 1, &range));
  return ok_status();
}

Status Context::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = upload_pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VK_CHECK(vkAllocateCommandBuffers(device_, &ai, &cmd));
  VkFence fence = VK_NULL_HANDLE;
  auto run = [&]() -> Status {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    record(cmd);
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(device_, &fci, nullptr, &fence));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK_CHECK(queue_submit(si, fence));
    const VkResult w = vkWaitForFences(device_, 1, &fence, VK_TRUE, kUploadTimeoutNs);
    if (w == VK_TIMEOUT) return fail(ErrorKind::Timeout, "an upload to the device did not finish within 30 s");
    VK_CHECK(w);
    return ok_status();
  };
  Status s = run();
  if (fence) vkDestroyFence(device_, fence, nullptr);
  vkFreeCommandBuffers(device_, upload_pool_, 1, &cmd);
  return s;
}

Status Context::upload_buffer(const GpuBuffer& dst, const void* data, VkDeviceSize size, VkDeviceSize dst_offset) {
  if (dst_offset + size > dst.size)
    return fail(ErrorKind::BadUsage, "upload of " + std::to_string(size) + " bytes at offset " +
                                         std::to_string(dst_offset) + " overruns a buffer of " +
                                         std::to_string(dst.size) + " bytes");
  if (dst.mapped) {  // host-visible: no staging needed
    std::memcpy(static_cast<char*>(dst.mapped) + dst_offset, data, size);
    return ok_status();
  }
  auto staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload, "staging");
  if (!staging) return staging.error();
  std::memcpy(staging->mapped, data, size);
  Status s = submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, dst_offset, size};
    vkCmdCopyBuffer(cmd, staging->buffer, dst.buffer, 1, &region);
    VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    mb.srcStageMask = VK_PIPELINE_STAGE_2_TRANSFER_BIT;
    mb.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    mb.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    mb.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    di.memoryBarrierCount = 1;
    di.pMemoryBarriers = &mb;
    fn_.cmd_pipeline_barrier2(cmd, &di);
  });
  destroy(*staging);
  return s;
}

Status Context::upload_image(const GpuImage& dst, const void* texels, VkDeviceSize size, VkImageLayout final_layout) {
  const uint32_t bpt = bytes_per_texel(dst.format);
  const VkDeviceSize expected = VkDeviceSize(dst.extent.width) * dst.extent.height * dst.depth * bpt * dst.layers;
  if (bpt == 0 || size != expected)
    return fail(ErrorKind::BadUsage, "image upload: " + std::to_string(size) + " bytes given, " +
                                         std::to_string(expected) + " expected for " +
                                         std::to_string(dst.extent.width) + "x" + std::to_string(dst.extent.height) + "x" +
                                         std::to_string(dst.depth) + " x " + std::to_string(dst.layers) +
                                         " layers (tightly packed mip 0)");
  auto staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload, "staging");
  if (!staging) return staging.error();
  std::memcpy(staging->mapped, texels, size);
  Status s = submit_and_wait([&](VkCommandBuffer cmd) {
    record_buffer_to_image(cmd, staging->buffer, dst, 0, dst.layers, VK_PIPELINE_STAGE_2_NONE, final_layout);
  });
  destroy(*staging);
  return s;
}

Status Context::upload_image_layer(const GpuImage& dst, uint32_t layer, const GpuBuffer& staging) {
  const VkDeviceSize bytes = VkDeviceSize(dst.extent.width) * dst.extent.height * bytes_per_texel(dst.format);
  if (layer >= dst.layers || staging.size < bytes)
    return fail(ErrorKind::Internal, "image layer upload: layer " + std::to_string(layer) + " of " +
                                         std::to_string(dst.layers) + ", staging " + std::to_string(staging.size) +
                                         " bytes for " + std::to_string(bytes));
  // All commands before: a frame submitted earlier may still sample this layer's old object.
  return submit_and_wait([&](VkCommandBuffer cmd) {
    record_buffer_to_image(cmd, staging.buffer, dst, layer, 1, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  });
}

void Context::record_buffer_to_image(VkCommandBuffer cmd, VkBuffer src, const GpuImage& dst, uint32_t first_layer,
                                     uint32_t layers, VkPipelineStageFlags2 after, VkImageLayout final_layout) const {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = after;
  b.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = dst.image;
  b.subresourceRange = {dst.aspect, 0, layers == dst.layers ? dst.mip_levels : 1, first_layer, layers};
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.imageMemoryBarrierCount = 1;
  di.pImageMemoryBarriers = &b;
  fn_.cmd_pipeline_barrier2(cmd, &di);
  VkBufferImageCopy region{};
  region.imageSubresource = {dst.aspect, 0, first_layer, layers};
  region.imageExtent = {dst.extent.width, dst.extent.height, dst.depth};
  vkCmdCopyBufferToImage(cmd, src, dst.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = final_layout;
  fn_.cmd_pipeline_barrier2(cmd, &di);
}

bool is_depth_format(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D16_UNORM_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return true;
    default: return false;
  }
}

VkImageAspectFlags aspect_of(VkFormat f) {
  return is_depth_format(f) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

uint32_t bytes_per_texel(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R8_UNORM: case VK_FORMAT_R8_UINT: case VK_FORMAT_R8_SRGB: return 1;
    case VK_FORMAT_R8G8_UNORM: case VK_FORMAT_R16_UINT: case VK_FORMAT_R16_UNORM: case VK_FORMAT_R16_SFLOAT:
    case VK_FORMAT_D16_UNORM: return 2;
    case VK_FORMAT_R8G8B8A8_UNORM: case VK_FORMAT_R8G8B8A8_SRGB: case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_R32_SFLOAT: case VK_FORMAT_R32_UINT: case VK_FORMAT_R16G16_SFLOAT: case VK_FORMAT_R16G16_UNORM:
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32: case VK_FORMAT_B10G11R11_UFLOAT_PACK32: case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_X8_D24_UNORM_PACK32: return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT: case VK_FORMAT_R32G32_SFLOAT: case VK_FORMAT_R16G16B16A16_UNORM: return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT: case VK_FORMAT_R32G32B32A32_UINT: return 16;
    default: return 0;
  }
}

}  // namespace mrgi::gpu
