/// \file
/// Running mrgi on the app's own Vulkan device. An app that already renders with Vulkan (a
/// tablet app, a headset's compositor client) hands create_runtime() its instance, physical
/// device, device and queue (DeviceSettings::app_device); mrgi then creates no instance or
/// device of its own, allocates only from the app's device, submits to the app's queue and
/// destroys none of them. In the order an app needs it:
///  1. vulkan_device_requirements(): the API version, device extensions and features to enable
///     when the app creates its device (merge them into its own);
///  2. vkCreateDevice with them, then an AppVulkanDevice naming the objects and what was enabled;
///  3. RuntimeSettings::device.app_device pointing to it: create_runtime() checks it and refuses
///     with BadUsage naming every missing extension or feature.
///
/// Waiting: mrgi waits only on fences of its own submissions, never on the whole queue or device
/// (no vkQueueWaitIdle, no vkDeviceWaitIdle), so the app's own work in flight never stalls it.
/// Queue access: Vulkan requires a queue's submissions to be externally synchronised. mrgi submits
/// from the thread that calls create_runtime, process() and flush() (and destroys from the one
/// that destroys the runtime); an app that submits to the same queue from another thread passes
/// lock_queue / unlock_queue, which mrgi calls around each of its vkQueueSubmit calls.
/// Validation: layers belong to the app's instance; DeviceSettings::validate must stay false with
/// an app device (enable VK_LAYER_KHRONOS_validation and a debug messenger on the instance).
/// Needs the Vulkan headers (Debian: libvulkan-dev); mrgi/runtime.h does not.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "mrgi/expected.h"
#include "mrgi/export.h"

namespace mrgi {

/// What mrgi needs enabled on a device it runs on. Holds its own feature structures; chain()
/// links them for VkDeviceCreateInfo::pNext (the pointers point into this object: do not copy or
/// move it between chain() and vkCreateDevice).
struct VulkanDeviceRequirements {
  /// VK_API_VERSION_1_3, or 1_2 where the device has only 1.2 or `vulkan_1_2` was asked for
  /// (synchronization2 and dynamic rendering then come from their KHR extensions).
  uint32_t api_version = 0;
  /// Device extensions to enable: VK_KHR_push_descriptor always; on 1.2 VK_KHR_synchronization2
  /// and VK_KHR_dynamic_rendering; VK_EXT_shader_atomic_float where the device has image float
  /// atomic add (optional: the light propagation volumes use it when it is enabled).
  std::vector<const char*> device_extensions;
  /// The features to enable, each only where the physical device has it (mrgi's techniques use
  /// them; create_runtime refuses an app device without one the physical device offers).
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceVulkan11Features vulkan11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features vulkan12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  /// synchronization2 and dynamicRendering: VkPhysicalDeviceVulkan13Features on 1.3, the
  /// extensions' own structures on 1.2 (chain() links the right ones).
  VkPhysicalDeviceVulkan13Features vulkan13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceSynchronization2Features synchronization2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  VkPhysicalDeviceDynamicRenderingFeatures dynamic_rendering{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic_float{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  bool atomic_float_present = false;  ///< the device has it: device_extensions lists it, chain() links it
  /// Links the structures above (`next` appended at the end) and returns &features.
  MRGI_API VkPhysicalDeviceFeatures2* chain(void* next = nullptr);
};

/// The requirements for `physical` (of `instance`). Device (naming what is missing) where the
/// device cannot run mrgi at all: Vulkan below 1.2, no push descriptors, no synchronization2 or
/// dynamic rendering, no queue family with graphics and compute.
MRGI_API Expected<VulkanDeviceRequirements> vulkan_device_requirements(VkInstance instance, VkPhysicalDevice physical,
                                                                        bool vulkan_1_2 = false);

/// The app's Vulkan objects for DeviceSettings::app_device. create_runtime copies this; the
/// objects must outlive the runtime.
struct AppVulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;  ///< a queue of `queue_family`
  uint32_t queue_family = 0;       ///< must have graphics and compute
  /// VkApplicationInfo::apiVersion the instance was created with (the version the app may use).
  uint32_t api_version = VK_API_VERSION_1_3;
  /// What the app passed to vkCreateDevice: its enabled device extensions and its feature chain
  /// (VkPhysicalDeviceFeatures2 and the structures linked from it, or null for none), read only
  /// during create_runtime. Vulkan has no query for what a device was created with.
  std::vector<std::string> enabled_extensions;
  const VkPhysicalDeviceFeatures2* enabled_features = nullptr;
  /// Optional: called around each of mrgi's queue submissions when the app submits to the same
  /// queue from another thread (both or neither).
  std::function<void()> lock_queue, unlock_queue;
};

/// Where a frame's composite goes on the app's device instead of host memory
/// (Runtime::process(frame, target); a runtime on DeviceSettings::app_device only): the app's
/// image, written by a copy at the end of the frame's own submission on the runtime's queue, so
/// an app that presents or samples it never copies it. The frame's FrameOutput then carries its
/// stats and light estimate but no image or mask (FrameStats::host_copy_bytes counts no output
/// bytes: the input's upload and, on a CPU device, the camera frame the host expands under the
/// composite; neither for a frame given as the app's images, AppInputImages). The image holds
/// the composite's sRGB-encoded bytes and, in alpha, the virtual mask (255 on the objects'
/// pixels, 0 elsewhere). When process() returns an error for the frame, its semaphores are not
/// used (nothing waits or signals them).
struct AppOutputImage {
  /// The output's size, one mip level and layer, created with VK_IMAGE_USAGE_TRANSFER_DST_BIT.
  VkImage image = VK_NULL_HANDLE;
  /// VK_FORMAT_R8G8B8A8_UNORM (the bytes as they are) or VK_FORMAT_R8G8B8A8_SRGB (a sampler
  /// decodes them to linear); others are refused.
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  /// Its layout when the copy starts (UNDEFINED: the old contents are not kept) and the layout
  /// the copy leaves it in (not UNDEFINED or PREINITIALIZED; PRESENT_SRC_KHR for a swapchain).
  VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  /// Optional binary semaphores: waited for before the copy (a swapchain image's acquire), and
  /// signalled when the image is written (what the app's present or draw waits for). Earlier
  /// work on the same queue is ordered before the copy without one.
  VkSemaphore wait = VK_NULL_HANDLE;
  VkSemaphore signal = VK_NULL_HANDLE;
};

/// A camera frame given as the app's images on its device (Runtime::process(frame, images)):
/// the frame's own submission copies them, on the runtime's queue and after `wait`, into the
/// runtime's buffers every pass reads (a transfer and a pass that packs the colour's 4 bytes a
/// pixel into 3), so the host copies no frame image. The images are read only by that
/// submission; the app may write them again once the frame's output is signalled (its
/// AppOutputImage::signal) or returned. Each is one mip level and layer, created with
/// VK_IMAGE_USAGE_TRANSFER_SRC_BIT, in the given layout before the frame and left in it after.
/// Their sizes must be the CameraSetup's colour and depth intrinsics' (Vulkan has no query for
/// an image's extent; a wrong size is the app's error, which the validation layer reports).
struct AppInputImages {
  /// The camera's sRGB-encoded colour (alpha ignored): VK_FORMAT_R8G8B8A8_UNORM or _SRGB, or
  /// VK_FORMAT_B8G8R8A8_UNORM or _SRGB (the bytes are taken as they are; SRGB is not decoded).
  VkImage color = VK_NULL_HANDLE;
  VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;
  VkImageLayout color_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  /// Depth registered to the colour in depth units (CameraSetup::depth_scale per metre, 0 =
  /// invalid): VK_FORMAT_R16_UINT or R16_UNORM (the 16 bits as they are), or D16_UNORM (its
  /// depth aspect's 16 bits: still depth units, not a projection's normalised depth).
  VkImage depth = VK_NULL_HANDLE;
  VkFormat depth_format = VK_FORMAT_R16_UINT;
  VkImageLayout depth_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  /// Optional binary semaphore waited for before the copies (the app's or the camera's writes).
  /// Earlier work on the same queue is ordered before them without one. Not the output's
  /// AppOutputImage::wait. Where process() returns an error it may have been waited for already
  /// (a priming run's submission waits for it first).
  VkSemaphore wait = VK_NULL_HANDLE;
};

}  // namespace mrgi
