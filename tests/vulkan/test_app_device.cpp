// mrgi on the app's own Vulkan device (mrgi/vulkan_device.h): the test plays the part of an app
// that owns its instance (with the validation layer and its own debug messenger) and device, runs
// the bundled sample through a runtime on them, and checks that the frames equal those of a
// runtime on its own device, that no validation message appears (including the layer's report of
// objects still alive when the app destroys its device: anything mrgi leaked), that the app's
// objects stay usable after the runtime is gone, and that a device without what mrgi needs is
// refused with the missing items named.
#include <gtest/gtest.h>

#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";

// The test's app: an instance with validation, lavapipe, a device made with mrgi's requirements
// (or without them), one queue.
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

// The sample's first `frames` outputs through a runtime made with `device` settings.
std::vector<ImageRGBA8> play_sample(const DeviceSettings& device, int frames, std::string* error) {
  std::vector<ImageRGBA8> out;
  auto capture = CaptureReader::open(kSample);
  if (!capture) {
    *error = capture.error().message;
    return out;
  }
  const CaptureInfo& info = capture->info();
  RuntimeSettings s;
  s.device = device;
  s.technique = "baseline";
  s.level = 1;
  s.exposure = info.exposure;
  auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
                           *capture->scene());
  if (!rt) {
    *error = rt.error().message;
    return out;
  }
  auto take = [&](Expected<std::vector<FrameOutput>>&& outs) {
    if (!outs) {
      *error = outs.error().message;
      return;
    }
    for (FrameOutput& o : *outs) out.push_back(std::move(o.image));
  };
  for (int i = 0; i < frames; ++i) {
    auto f = capture->read_frame(size_t(i));
    if (!f) {
      *error = f.error().message;
      return out;
    }
    f->index = i;
    take((*rt)->process(*f));
  }
  take((*rt)->flush());
  return out;
}

TEST(AppDevice, FramesEqualTheRuntimesOwnDeviceWithoutValidationMessages) {
  std::vector<ImageRGBA8> on_app;
  {
    AppVulkan app(true);
    ASSERT_TRUE(app.ok()) << "the test's app could not create its instance and device (validation layer installed?)";
    DeviceSettings d;
    d.app_device = &app.app;
    std::string error;
    on_app = play_sample(d, 4, &error);
    ASSERT_TRUE(error.empty()) << error;
    // The runtime is gone; the app's device and queue still work.
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 256;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateBuffer(app.device, &bci, nullptr, &buffer), VK_SUCCESS);
    vkDestroyBuffer(app.device, buffer, nullptr);
    EXPECT_EQ(vkQueueWaitIdle(app.queue), VK_SUCCESS);
    for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
  }
  DeviceSettings own;
  own.device = "llvmpipe";
  std::string error;
  const std::vector<ImageRGBA8> on_own = play_sample(own, 4, &error);
  ASSERT_TRUE(error.empty()) << error;
  ASSERT_EQ(on_app.size(), 4u);
  ASSERT_EQ(on_own.size(), 4u);
  for (size_t i = 0; i < on_app.size(); ++i) {
    ASSERT_EQ(on_app[i].width, on_own[i].width);
    EXPECT_TRUE(on_app[i].data == on_own[i].data) << "frame " << i << " differs from the runtime's own device";
  }
}

TEST(AppDevice, AVulkan12AppsDeviceRunsTheExtensionPath) {
  AppVulkan app(true, true);
  ASSERT_TRUE(app.ok());
  EXPECT_EQ(app.requirements.api_version, VK_API_VERSION_1_2);
  DeviceSettings d;
  d.app_device = &app.app;
  std::string error;
  const auto frames = play_sample(d, 2, &error);
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_EQ(frames.size(), 2u);
  vkDestroyDevice(app.device, nullptr);
  app.device = VK_NULL_HANDLE;
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

TEST(AppDevice, NoValidationMessageWhenTheAppDestroysItsDeviceAfterTheRuntime) {
  // vkDestroyDevice with the layer on reports every object created on the device and not yet
  // destroyed: the runtime must have destroyed all of its own.
  AppVulkan app(true);
  ASSERT_TRUE(app.ok());
  DeviceSettings d;
  d.app_device = &app.app;
  std::string error;
  play_sample(d, 2, &error);
  ASSERT_TRUE(error.empty()) << error;
  vkDestroyDevice(app.device, nullptr);
  app.device = VK_NULL_HANDLE;
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

TEST(AppDevice, ADeviceWithoutWhatMrgiNeedsIsRefusedNamingEachMissingItem) {
  AppVulkan app(false);  // created with no extensions and no features
  ASSERT_TRUE(app.ok());
  DeviceSettings d;
  d.app_device = &app.app;
  std::string error;
  const auto frames = play_sample(d, 1, &error);
  EXPECT_TRUE(frames.empty());
  EXPECT_NE(error.find("DeviceSettings::app_device"), std::string::npos) << error;
  EXPECT_NE(error.find(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME), std::string::npos) << error;
  EXPECT_NE(error.find("VkPhysicalDeviceVulkan13Features::synchronization2"), std::string::npos) << error;
  EXPECT_NE(error.find("VkPhysicalDeviceVulkan13Features::dynamicRendering"), std::string::npos) << error;
  EXPECT_NE(error.find("vulkan_device_requirements"), std::string::npos) << error;
}

TEST(AppDevice, BadHandlesAndSettingsAreRefusedByName) {
  AppVulkan app(true);
  ASSERT_TRUE(app.ok());
  std::string error;
  {
    AppVulkanDevice missing = app.app;
    missing.queue = VK_NULL_HANDLE;
    DeviceSettings d;
    d.app_device = &missing;
    play_sample(d, 1, &error);
    EXPECT_NE(error.find("instance, physical_device, device and queue must all be set"), std::string::npos) << error;
  }
  {
    AppVulkanDevice bad_family = app.app;
    bad_family.queue_family = 99;
    DeviceSettings d;
    d.app_device = &bad_family;
    play_sample(d, 1, &error);
    EXPECT_NE(error.find("queue_family 99"), std::string::npos) << error;
  }
  {
    AppVulkanDevice half_lock = app.app;
    half_lock.lock_queue = [] {};
    DeviceSettings d;
    d.app_device = &half_lock;
    play_sample(d, 1, &error);
    EXPECT_NE(error.find("lock_queue and unlock_queue go together"), std::string::npos) << error;
  }
  {
    DeviceSettings d;
    d.app_device = &app.app;
    d.validate = true;
    play_sample(d, 1, &error);
    EXPECT_NE(error.find("validation layers belong to the app's instance"), std::string::npos) << error;
  }
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

TEST(AppDevice, TheAppsQueueLockWrapsEverySubmission) {
  AppVulkan app(true);
  ASSERT_TRUE(app.ok());
  int depth = 0, locks = 0, max_depth = 0;
  app.app.lock_queue = [&] {
    ++locks;
    max_depth = std::max(max_depth, ++depth);
  };
  app.app.unlock_queue = [&] { --depth; };
  DeviceSettings d;
  d.app_device = &app.app;
  std::string error;
  const auto frames = play_sample(d, 3, &error);
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_EQ(frames.size(), 3u);
  EXPECT_GE(locks, 3);  // start-up uploads and at least one submission a frame
  EXPECT_EQ(depth, 0);
  EXPECT_EQ(max_depth, 1);
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

}  // namespace
}  // namespace mrgi::test
