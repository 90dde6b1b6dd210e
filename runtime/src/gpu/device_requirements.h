// What mrgi enables on a device (mrgi/vulkan_device.h vulkan_device_requirements), shared by the
// device mrgi creates itself (gpu/context.cpp) and the check of an app's device: one list, so the
// two cannot drift apart.
#pragma once
#include <string>

#include "mrgi/expected.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::gpu {

bool device_has_extension(VkPhysicalDevice pd, const char* name);

// What the app's device has enabled of what mrgi uses, after check_app_device.
struct AppDeviceEnabled {
  bool api_1_3 = false;          // synchronization2 and dynamic rendering are core (else KHR)
  bool large_points = false;     // VkPhysicalDeviceFeatures::largePoints
  bool image_float_atomic_add = false;
};

// BadUsage naming DeviceSettings::app_device's field and every missing extension or feature
// (by its Vulkan structure and member name) where `app` cannot run mrgi; what it enabled of the
// optional ones otherwise. `vulkan_1_2`: DeviceSettings::vulkan_1_2.
Expected<AppDeviceEnabled> check_app_device(const AppVulkanDevice& app, bool vulkan_1_2);

}  // namespace mrgi::gpu
