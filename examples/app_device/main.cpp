// An app that already renders with Vulkan runs mrgi on its own instance, device and queue
// (mrgi/vulkan_device.h): it asks mrgi what to enable, creates its device with that (and what it
// needs itself), hands the objects to create_runtime, plays a recorded capture through the
// runtime, and goes on using its device after the runtime is gone.
//
//   app_device CAPTURE_DIR [FRAMES]
//
// Prints the device, what was enabled for mrgi and each frame's output. Exit 0 when every frame
// came back and the device still works afterwards.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include <mrgi/platform/capture.h>
#include <mrgi/runtime.h>
#include <mrgi/vulkan_device.h>

namespace {

int fail(const std::string& what) {
  std::fprintf(stderr, "error: %s\n", what.c_str());
  return 1;
}

// The app's device: lavapipe if present (the CPU device every machine here has), else the first.
VkPhysicalDevice pick_device(VkInstance instance) {
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(instance, &n, devices.data());
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p{};
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) return d;
  }
  return devices.empty() ? VK_NULL_HANDLE : devices[0];
}

uint32_t graphics_compute_family(VkPhysicalDevice device) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &n, families.data());
  for (uint32_t i = 0; i < n; ++i)
    if ((families[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) == (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
      return i;
  return ~0u;
}

// Plays `frames` frames of the capture through a runtime on the app's device.
int play(const mrgi::AppVulkanDevice& app, const std::string& capture_dir, int frames) {
  auto capture = mrgi::CaptureReader::open(capture_dir);
  if (!capture) return fail(capture.error().message);
  const mrgi::CaptureInfo& info = capture->info();
  mrgi::RuntimeSettings settings;
  settings.device.app_device = &app;
  settings.exposure = info.exposure;
  auto runtime = mrgi::create_runtime(
      settings, mrgi::CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
      *capture->scene());
  if (!runtime) return fail(runtime.error().message);
  std::printf("runtime on the app's device: %s\n", (*runtime)->device().name.c_str());
  int returned = 0;
  auto report = [&](const std::vector<mrgi::FrameOutput>& outs) {
    for (const mrgi::FrameOutput& o : outs) {
      std::printf("frame %lld: %dx%d, cost %.1f ms\n", static_cast<long long>(o.stats.frame_index), o.image.width,
                  o.image.height, o.stats.cost_ms);
      ++returned;
    }
  };
  const int n = std::min<int>(frames, int(capture->frame_count()));
  for (int i = 0; i < n; ++i) {
    auto frame = capture->read_frame(size_t(i));
    if (!frame) return fail(frame.error().message);
    frame->index = i;
    auto outs = (*runtime)->process(*frame);
    if (!outs) return fail(outs.error().message);
    report(*outs);
  }
  auto rest = (*runtime)->flush();
  if (!rest) return fail(rest.error().message);
  report(*rest);
  return returned == n ? 0 : fail(std::to_string(returned) + " of " + std::to_string(n) + " frames came back");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s CAPTURE_DIR [FRAMES]\n", argv[0]);
    return 2;
  }
  const int frames = argc > 2 ? std::atoi(argv[2]) : 4;

  // The app's instance and device, created as the app wants them.
  VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  ai.pApplicationName = "app_device";
  ai.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &ai;
  VkInstance instance = VK_NULL_HANDLE;
  if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS) return fail("vkCreateInstance failed");
  VkPhysicalDevice physical = pick_device(instance);
  const uint32_t family = physical ? graphics_compute_family(physical) : ~0u;
  if (family == ~0u) return fail("no Vulkan device with a graphics and compute queue");

  // What mrgi needs enabled, merged with the app's own needs (none beyond it here).
  auto needs = mrgi::vulkan_device_requirements(instance, physical);
  if (!needs) return fail(needs.error().message);
  std::printf("enabling for mrgi: Vulkan %u.%u,", VK_API_VERSION_MAJOR(needs->api_version),
              VK_API_VERSION_MINOR(needs->api_version));
  for (const char* e : needs->device_extensions) std::printf(" %s", e);
  std::printf("\n");
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = needs->chain();
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(needs->device_extensions.size());
  dci.ppEnabledExtensionNames = needs->device_extensions.data();
  VkDevice device = VK_NULL_HANDLE;
  if (vkCreateDevice(physical, &dci, nullptr, &device) != VK_SUCCESS) return fail("vkCreateDevice failed");
  VkQueue queue = VK_NULL_HANDLE;
  vkGetDeviceQueue(device, family, 0, &queue);

  mrgi::AppVulkanDevice app;
  app.instance = instance;
  app.physical_device = physical;
  app.device = device;
  app.queue = queue;
  app.queue_family = family;
  app.api_version = ai.apiVersion;
  for (const char* e : needs->device_extensions) app.enabled_extensions.push_back(e);
  app.enabled_features = &needs->features;
  int status = play(app, argv[1], frames);

  // The runtime is gone: the device is still the app's, with its work and objects.
  if (status == 0) {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 4096;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    if (vkCreateBuffer(device, &bci, nullptr, &buffer) != VK_SUCCESS || vkQueueWaitIdle(queue) != VK_SUCCESS)
      status = fail("the app's device no longer works after the runtime");
    vkDestroyBuffer(device, buffer, nullptr);
    if (status == 0) std::printf("the app's device still works after the runtime\n");
  }
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  return status;
}
