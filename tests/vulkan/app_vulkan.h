// The test's app for the tests of mrgi on the app's own Vulkan device (mrgi/vulkan_device.h): an
// instance with the validation layer and its own debug messenger, lavapipe, a device made with
// mrgi's requirements (or without them), one queue.
#pragma once
#include <mutex>
#include <string>
#include <vector>

#include "mrgi/vulkan_device.h"

namespace mrgi::test {

class AppVulkan {
 public:
  // vulkan_1_2: the instance asks for Vulkan 1.2 (a 1.2 app; mrgi then takes synchronization2 and
  // dynamic rendering from their extensions).
  explicit AppVulkan(bool with_requirements, bool vulkan_1_2 = false) {
    const uint32_t api = vulkan_1_2 ? VK_API_VERSION_1_2 : VK_API_VERSION_1_3;
    VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    ai.apiVersion = api;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mci.pfnUserCallback = &AppVulkan::on_message;
    mci.pUserData = this;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pNext = &mci;  // also reports what happens in vkCreateInstance / vkDestroyInstance
    ici.pApplicationInfo = &ai;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &ext;
    if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS) return;
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    create_messenger(instance, &mci, nullptr, &messenger);
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(instance, &n, pds.data());
    for (VkPhysicalDevice pd : pds) {
      VkPhysicalDeviceProperties p{};
      vkGetPhysicalDeviceProperties(pd, &p);
      if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) physical = pd;
    }
    if (!physical) return;
    uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &nq, families.data());
    for (uint32_t i = 0; i < nq; ++i)
      if ((families[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
          (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) {
        family = i;
        break;
      }
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (with_requirements) {
      auto r = vulkan_device_requirements(instance, physical, vulkan_1_2);
      if (!r) return;
      requirements = std::move(*r);
      dci.pNext = requirements.chain();
      dci.enabledExtensionCount = uint32_t(requirements.device_extensions.size());
      dci.ppEnabledExtensionNames = requirements.device_extensions.data();
      for (const char* e : requirements.device_extensions) app.enabled_extensions.push_back(e);
      app.enabled_features = &requirements.features;
    }
    if (vkCreateDevice(physical, &dci, nullptr, &device) != VK_SUCCESS) return;
    vkGetDeviceQueue(device, family, 0, &queue);
    app.instance = instance;
    app.physical_device = physical;
    app.device = device;
    app.queue = queue;
    app.queue_family = family;
    app.api_version = api;
  }
  ~AppVulkan() {
    if (device) vkDestroyDevice(device, nullptr);  // validation reports any child object still alive
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }
  bool ok() const { return queue != VK_NULL_HANDLE; }
  std::vector<std::string> messages() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  VulkanDeviceRequirements requirements;
  AppVulkanDevice app;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<AppVulkan*>(user);
    std::lock_guard<std::mutex> lock(self->mutex_);
    self->messages_.push_back(data && data->pMessage ? data->pMessage : "?");
    return VK_FALSE;
  }
  std::mutex mutex_;
  std::vector<std::string> messages_;
};


}  // namespace mrgi::test
