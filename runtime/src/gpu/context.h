// The Vulkan context: instance, one physical device, one graphics+compute queue, memory
// accounting, start-up uploads and the optional validation layer whose messages are recorded.
// Headless (no surface). Requires Vulkan 1.2 with synchronization2, dynamic rendering and
// VK_KHR_push_descriptor (Mesa lavapipe 22.3+, current desktop and mobile drivers); a device
// without them is refused at creation with a message naming what is missing.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/runtime.h"

namespace mrgi::gpu {

// Where a resource's memory lives.
enum class MemoryUsage {
  DeviceLocal,  // GPU only
  Upload,       // host-visible + coherent, persistently mapped: host writes, GPU reads
  Readback,     // host-visible (cached if available), persistently mapped: GPU writes, host reads
  // host-visible + coherent, cached if available, persistently mapped: the host writes and the
  // GPU reads it, or the GPU writes it, and the host reads it back too (the camera uploads, which
  // the host's readers of the camera take frames later: frame/camera_view.h); uncached
  // write-combined memory would make those reads slow on a discrete GPU.
  UploadHostRead,
};

// A buffer with its own VkDeviceMemory. `mapped` is non-null for Upload/Readback.
struct GpuBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;          // requested size in bytes
  VkDeviceSize allocated = 0;     // bytes of device memory behind it (>= size)
  VkBufferUsageFlags usage = 0;
  MemoryUsage memory_usage = MemoryUsage::DeviceLocal;
  bool coherent = true;           // false: call Context::invalidate before host reads
  void* mapped = nullptr;
  VkBufferView texel_view = VK_NULL_HANDLE;  // BufferDesc::texel_format's view; destroyed with it
};

// A 2D image (optionally layered / mipmapped) or a 3D image (depth > 1, one layer), with one
// view over all levels and layers and, when mipmapped, one view per level (storage writes of a
// mip chain bind a single level).
struct ImageCreateDesc {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  uint32_t width = 1, height = 1;
  uint32_t depth = 1;
  uint32_t mip_levels = 1;
  uint32_t layers = 1;            // > 1: a 2D array view
  bool array_view = false;        // a 2D array view with one layer too
  VkImageUsageFlags usage = 0;
  std::string name;               // debug name (shown by validation messages)
};
struct GpuImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  uint32_t depth = 1;             // > 1: a 3D image
  uint32_t mip_levels = 1, layers = 1;
  std::vector<VkImageView> mip_views;  // one per level when mip_levels > 1
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  VkImageUsageFlags usage = 0;
  VkDeviceSize allocated = 0;
};

// Samplers every pass may use, created once.
struct StandardSamplers {
  VkSampler linear_clamp = VK_NULL_HANDLE;
  VkSampler nearest_clamp = VK_NULL_HANDLE;
  VkSampler linear_repeat = VK_NULL_HANDLE;
  VkSampler shadow_compare = VK_NULL_HANDLE;  // linear, compare LESS_OR_EQUAL, clamp to border 1
};

// Entry points that are core in 1.3 but extensions in 1.2 (sync2, dynamic rendering), fetched
// with the right name for the device's API version.
struct DeviceFunctions {
  PFN_vkCmdPipelineBarrier2 cmd_pipeline_barrier2 = nullptr;
  PFN_vkCmdWriteTimestamp2 cmd_write_timestamp2 = nullptr;
  PFN_vkQueueSubmit2 queue_submit2 = nullptr;
  PFN_vkCmdBeginRendering cmd_begin_rendering = nullptr;
  PFN_vkCmdEndRendering cmd_end_rendering = nullptr;
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set = nullptr;
};

// The device index `selector` picks among `devices` (rules of DeviceSettings::device, with the
// $MRGI_DEVICE step already applied by the caller). BadUsage listing the devices if none matches.
Expected<uint32_t> select_device_index(const std::vector<DeviceInfo>& devices,
                                       const std::string& selector);
// DeviceSettings::device, or $MRGI_DEVICE when that is empty.
std::string effective_device_selector(const DeviceSettings& settings);

class Context {
 public:
  // Selects the device per DeviceSettings (see runtime.h) and creates everything.
  static Expected<std::unique_ptr<Context>> create(const DeviceSettings& settings);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  // The device is the app's (DeviceSettings::app_device): mrgi destroys none of the Vulkan
  // objects it was given and waits only on its own fences (mrgi/vulkan_device.h).
  bool app_device() const { return !owns_device_; }
  // vkQueueSubmit2 / vkQueueSubmit on queue(), inside the app's queue lock where it gave one.
  // Every submission of mrgi's goes through these.
  VkResult queue_submit2(const VkSubmitInfo2& submit, VkFence fence) const;
  VkResult queue_submit(const VkSubmitInfo& submit, VkFence fence) const;
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  // Nanoseconds per timestamp tick (VkPhysicalDeviceLimits::timestampPeriod).
  double timestamp_period_ns() const { return properties_.limits.timestampPeriod; }
  // Valid bits of the queue's timestamps (0: the queue has none; timings are then refused).
  uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
  const StandardSamplers& samplers() const { return samplers_; }
  // vkCmdPushDescriptorSetKHR, fetched at creation.
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set() const { return fn_.cmd_push_descriptor_set; }
  const DeviceFunctions& fn() const { return fn_; }

  // Validation (DeviceSettings::validate): every warning and error message, in order.
  bool validation_enabled() const { return validate_; }
  // Whether sync2 and dynamic rendering are core (1.3) or their KHR extensions (1.2 path).
  bool api_1_3() const { return api_1_3_; }
  // imageAtomicAdd on 32-bit float images and texel buffers (VK_EXT_shader_atomic_float), enabled
  // where the device has it.
  bool image_float_atomic_add() const { return image_float_atomic_add_; }
  // The largest point a vertex shader may ask for (gl_PointSize, pixels): the limits'
  // pointSizeRange where the device has largePoints (enabled then), else 1.
  float max_point_size() const { return large_points_ ? properties_.limits.pointSizeRange[1] : 1.0f; }
  size_t validation_message_count() const;
  std::vector<std::string> validation_messages() const;
  void clear_validation_messages();

  // Resources. Each has its own allocation; all are meant to be made at start-up. The counters
  // below are exact (sum of VkMemoryRequirements sizes of live allocations).
  Expected<GpuBuffer> create_buffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                    MemoryUsage memory, const std::string& name);
  Expected<GpuImage> create_image(const ImageCreateDesc& desc);
  void destroy(GpuBuffer& buffer);
  void destroy(GpuImage& image);
  uint64_t allocated_bytes() const { return allocated_bytes_; }
  double memory_mib() const { return double(allocated_bytes_) / (1024.0 * 1024.0); }
  uint64_t allocation_count() const { return allocation_count_; }
  // Makes GPU writes visible to the host for non-coherent Readback memory (no-op if coherent).
  Status invalidate(const GpuBuffer& buffer);

  // Start-up helpers: record into a one-shot command buffer, submit and wait. Not for frames.
  Status submit_and_wait(const std::function<void(VkCommandBuffer)>& record);
  // Copies bytes into a device-local buffer through a temporary staging buffer.
  Status upload_buffer(const GpuBuffer& dst, const void* data, VkDeviceSize size,
                       VkDeviceSize dst_offset = 0);
  // Uploads tightly packed texels into mip 0 of every layer (layer after layer) and leaves the
  // image in `final_layout`.
  Status upload_image(const GpuImage& dst, const void* texels, VkDeviceSize size,
                      VkImageLayout final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);

  // Copies mip 0 of one layer from `staging` (tightly packed, its first bytes) while frames may
  // be on the queue: ordered after every earlier submission (a frame still reading the layer's
  // old contents finishes first, so this waits for the frames in flight), the layer left in
  // SHADER_READ_ONLY_OPTIMAL. No memory is allocated (a command buffer and a fence are made for
  // it, as submit_and_wait does); waits on its own fence only. For an object added at run time.
  Status upload_image_layer(const GpuImage& dst, uint32_t layer, const GpuBuffer& staging);

  // Into `cmd`: layers [first_layer, first_layer + layers) of `dst` (mip 0; every mip's layout
  // for a whole-image copy) from UNDEFINED to TRANSFER_DST after the commands of stages `after`,
  // a copy from `src` (tightly packed), then to `final_layout` for every later command.
  void record_buffer_to_image(VkCommandBuffer cmd, VkBuffer src, const GpuImage& dst, uint32_t first_layer,
                              uint32_t layers, VkPipelineStageFlags2 after, VkImageLayout final_layout) const;

  // Debug names through VK_EXT_debug_utils when validation is on (no-op otherwise).
  void set_name(VkObjectType type, uint64_t handle, const std::string& name) const;

  // Internal: called by the debug messenger.
  void record_validation_message(std::string message);

 private:
  Context() = default;
  Status init(const DeviceSettings& settings);
  // init() for DeviceSettings::app_device: the app's objects, checked, instead of new ones.
  Status init_app_device(const DeviceSettings& settings);
  // init()'s steps, in its order.
  Status init_instance(const DeviceSettings& settings);
  Status select_physical_device(const DeviceSettings& settings);
  Status choose_queue_family(const std::string& who);
  Status create_device(const std::string& who);
  Status load_device_functions(const std::string& who);
  Status create_upload_pool();
  Status create_samplers();
  Expected<VkDeviceMemory> allocate(const VkMemoryRequirements& req, MemoryUsage usage,
                                    bool* coherent);

  VkInstance instance_ = VK_NULL_HANDLE;
  bool owns_device_ = true;  // false: instance_, device_ and queue_ are the app's
  std::function<void()> lock_queue_, unlock_queue_;  // AppVulkanDevice's (app devices only)
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  uint32_t timestamp_valid_bits_ = 0;
  VkCommandPool upload_pool_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  DeviceInfo info_;
  StandardSamplers samplers_;
  DeviceFunctions fn_;
  PFN_vkSetDebugUtilsObjectNameEXT set_object_name_ = nullptr;
  bool validate_ = false;
  bool api_1_3_ = false;
  bool poison_memory_ = false;  // DeviceSettings::poison_memory
  bool image_float_atomic_add_ = false;
  bool large_points_ = false;
  uint64_t allocated_bytes_ = 0;
  uint64_t allocation_count_ = 0;
  mutable std::mutex messages_mutex_;
  std::vector<std::string> messages_;
};

// Image aspect for a format (depth formats -> DEPTH, else COLOR).
VkImageAspectFlags aspect_of(VkFormat format);
bool is_depth_format(VkFormat format);
// Bytes per texel of the uncompressed formats mrgi uses (0 for others).
uint32_t bytes_per_texel(VkFormat format);

}  // namespace mrgi::gpu
