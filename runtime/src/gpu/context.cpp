// The Vulkan context (gpu/context.h): instance and device set-up with the 1.3 or 1.2 entry points,
// device listing and selection, validation messages; memory, images and uploads are in
// context_resources.cpp.
#include "gpu/context.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "gpu/device_requirements.h"
#include "gpu/vk_check.h"
#include "mrgi/vulkan_device.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mrgi::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
  if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                  VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
    const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    static_cast<Context*>(user)->record_validation_message(
        std::string("validation ") + level + ": " + (data && data->pMessage ? data->pMessage : "?"));
  }
  return VK_FALSE;
}

std::string device_type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual-gpu";
    default: return "other";
  }
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::string version_string(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

std::string device_list_text(const std::vector<DeviceInfo>& devices) {
  std::string s;
  for (const auto& d : devices) s += "\n  " + std::to_string(d.index) + ": " + d.name + " (" + d.type + ")";
  return devices.empty() ? std::string("\n  (no Vulkan devices)") : s;
}

bool layer_available(const char* name) {
  uint32_t n = 0;
  if (vkEnumerateInstanceLayerProperties(&n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(n);
  if (vkEnumerateInstanceLayerProperties(&n, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

// A bare instance for listing devices and the one a Context keeps.
// api_version: the highest Vulkan version the process uses (1.3, or 1.2 for DeviceSettings::
// vulkan_1_2).
Expected<VkInstance> create_instance(bool validate, const VkDebugUtilsMessengerCreateInfoEXT* messenger,
                                     uint32_t api_version = VK_API_VERSION_1_3) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "mrgi";
  app.pEngineName = "mrgi";
  app.apiVersion = api_version;
  std::vector<const char*> layers, extensions;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  // Synchronization validation checks what the frame graph derives: a missing barrier is a
  // message, and tests fail on any message.
  const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  if (validate) {
    if (!layer_available(kValidationLayer))
      return fail(ErrorKind::Device, std::string("validation requested but ") + kValidationLayer +
                                         " is not installed (Debian package vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    features.pNext = messenger;
  }
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pNext = validate ? &features : nullptr;
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = uint32_t(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = uint32_t(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    return fail(ErrorKind::NotFound, "no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER); "
                                     "install mesa-vulkan-drivers for lavapipe");
  VK_CHECK(r);
  return instance;
}

Expected<std::vector<VkPhysicalDevice>> physical_devices(VkInstance instance) {
  uint32_t n = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> pds(n);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, pds.data()));
  pds.resize(n);
  return pds;
}

DeviceInfo describe(VkPhysicalDevice pd, uint32_t index) {
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &driver;
  vkGetPhysicalDeviceProperties2(pd, &props);
  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(pd, &mem);
  DeviceInfo d;
  d.index = index;
  d.name = props.properties.deviceName;
  d.type = device_type_name(props.properties.deviceType);
  d.driver = std::string(driver.driverName) + " " + driver.driverInfo;
  d.api_version = props.properties.apiVersion;
  for (uint32_t i = 0; i < mem.memoryHeapCount; ++i)
    if (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      d.device_local_mib += mem.memoryHeaps[i].size / (1024 * 1024);
  return d;
}

std::vector<DeviceInfo> describe_all(const std::vector<VkPhysicalDevice>& pds) {
  std::vector<DeviceInfo> out;
  for (uint32_t i = 0; i < pds.size(); ++i) out.push_back(describe(pds[i], i));
  return out;
}

template <class T>
T load_device_fn(VkDevice device, const char* core, const char* khr) {
  auto f = vkGetDeviceProcAddr(device, core);
  if (!f && khr) f = vkGetDeviceProcAddr(device, khr);
  return reinterpret_cast<T>(f);
}

}  // namespace

// With validation requested, listing fails loudly if the layer is not installed.
Expected<VkInstance> create_instance_for_listing(bool validate) { return create_instance(validate, nullptr); }
Expected<std::vector<VkPhysicalDevice>> physical_devices_for_listing(VkInstance i) { return physical_devices(i); }
std::vector<DeviceInfo> describe_all_devices(const std::vector<VkPhysicalDevice>& pds) { return describe_all(pds); }

std::string effective_device_selector(const DeviceSettings& settings) {
  if (!settings.device.empty()) return settings.device;
  const char* env = std::getenv("MRGI_DEVICE");
  return env ? std::string(env) : std::string();
}

Expected<uint32_t> select_device_index(const std::vector<DeviceInfo>& devices,
                                       const std::string& selector) {
  if (devices.empty())
    return fail(ErrorKind::NotFound, "no Vulkan devices (install mesa-vulkan-drivers for lavapipe)");
  if (selector.empty()) {
    for (const auto& d : devices) {
      const std::string n = lower(d.name);
      if (n.find("llvmpipe") != std::string::npos || n.find("lavapipe") != std::string::npos) return d.index;
    }
    return 0u;
  }
  const bool numeric = std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c); });
  if (numeric) {
    const unsigned long i = selector.size() > 9 ? ~0ul : std::stoul(selector);
    if (i < devices.size()) return uint32_t(i);
    return fail(ErrorKind::BadUsage, "device selector '" + selector + "': index out of range (" +
                                         std::to_string(devices.size()) + " devices):" + device_list_text(devices));
  }
  const std::string want = lower(selector);
  // Aliases by kind, before names: Mesa's lavapipe names itself "llvmpipe (LLVM ...)", so the
  // name the documentation uses would match nothing as a substring.
  auto first_of_type = [&](std::initializer_list<const char*> types) -> std::optional<uint32_t> {
    for (const char* t : types)
      for (const auto& d : devices)
        if (d.type == t) return d.index;
    return std::nullopt;
  };
  std::optional<uint32_t> alias;
  const bool cpu_alias = want == "cpu" || want == "lavapipe" || want == "llvmpipe";
  if (cpu_alias) alias = first_of_type({"cpu"});
  if (want == "gpu") alias = first_of_type({"discrete-gpu", "integrated-gpu", "virtual-gpu"});
  if (alias) return *alias;
  if (cpu_alias || want == "gpu")
    return fail(ErrorKind::BadUsage, "device selector '" + selector + "': no " +
                                         (cpu_alias ? "CPU (lavapipe) device" : "GPU device") +
                                         " among the Vulkan devices (install mesa-vulkan-drivers for lavapipe):" +
                                         device_list_text(devices));
  for (const auto& d : devices)
    if (lower(d.name).find(want) != std::string::npos) return d.index;
  return fail(ErrorKind::BadUsage, "device selector '" + selector +
                                       "' matches no device name (use an index, a name substring, or cpu / "
                                       "lavapipe / gpu):" +
                                       device_list_text(devices));
}

namespace {
// A CPU driver (lavapipe) allocates its per-frame work (bins, vertex buffers of the draw
// module, coroutine stacks) with malloc and frees it at the end of the frame. With glibc's
// defaults, blocks above the dynamic mmap threshold are mmapped and unmapped again and the heap
// top is trimmed, so every frame page-faults its memory back in: measured on the baseline
// lowest level (desk_spot, 640x480, x2 threads), 111 ms a frame in a fresh process against 50 ms
// with freed memory kept (the shadow pass alone 54 -> 18.5 ms). Keeping it is what a fixed-budget
// runtime wants anyway: memory reaches its peak in the first frames and stays there.
void keep_freed_memory() {
#if defined(__GLIBC__)
  static const bool done = [] {
    mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);  // glibc's largest: blocks up to 32 MiB stay on the heap
    mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
    mallopt(M_TOP_PAD, 64 * 1024 * 1024);
    return true;
  }();
  (void)done;
#endif
}
}  // namespace

Expected<std::unique_ptr<Context>> Context::create(const DeviceSettings& settings) {
  if (settings.keep_freed_memory) keep_freed_memory();
  std::unique_ptr<Context> ctx(new Context());
  MRGI_TRY(ctx->init(settings));
  return ctx;
}

Status Context::init(const DeviceSettings& settings) {
  validate_ = settings.validate;
  const char* poison_env = std::getenv("MRGI_POISON_MEMORY");
  poison_memory_ = settings.poison_memory || (poison_env != nullptr && std::string(poison_env) == "1");
  if (settings.app_device) return init_app_device(settings);
  MRGI_TRY(init_instance(settings));
  MRGI_TRY(select_physical_device(settings));
  const std::string who = "device " + std::to_string(info_.index) + " '" + info_.name + "'";
  if (properties_.apiVersion < VK_API_VERSION_1_2)
    return fail(ErrorKind::Device, who + " has Vulkan " + version_string(properties_.apiVersion) +
                                       "; mrgi needs 1.2 or later");
  // The 1.3 entry points only where both the device and the settings allow them.
  const bool is13 = properties_.apiVersion >= VK_API_VERSION_1_3 && !settings.vulkan_1_2;
  api_1_3_ = is13;

  MRGI_TRY(choose_queue_family(who));
  MRGI_TRY(create_device(who));
  MRGI_TRY(load_device_functions(who));
  MRGI_TRY(create_upload_pool());
  MRGI_TRY(create_samplers());
  return ok_status();
}

// The instance at the settings' API version, with the validation messenger when validating.
Status Context::init_instance(const DeviceSettings& settings) {
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mci.pfnUserCallback = debug_callback;
  mci.pUserData = this;
  auto instance = create_instance(validate_, &mci, settings.vulkan_1_2 ? VK_API_VERSION_1_2 : VK_API_VERSION_1_3);
  if (!instance) return instance.error();
  instance_ = *instance;
  if (validate_) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    set_object_name_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
    if (!create_messenger) return fail(ErrorKind::Device, "VK_EXT_debug_utils: vkCreateDebugUtilsMessengerEXT missing");
    VK_CHECK(create_messenger(instance_, &mci, nullptr, &messenger_));
  }
  return ok_status();
}

// The settings' device of those the instance lists, with its properties.
Status Context::select_physical_device(const DeviceSettings& settings) {
  auto pds = physical_devices(instance_);
  if (!pds) return pds.error();
  const std::vector<DeviceInfo> devices = describe_all(*pds);
  auto chosen = select_device_index(devices, effective_device_selector(settings));
  if (!chosen) return chosen.error();
  physical_ = (*pds)[*chosen];
  info_ = devices[*chosen];
  info_.selected = true;
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_properties_);
  return ok_status();
}

// Queue: the first family with graphics and compute.
Status Context::choose_queue_family(const std::string& who) {
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, families.data());
  bool found = false;
  for (uint32_t i = 0; i < nq && !found; ++i) {
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    if ((families[i].queueFlags & need) == need) {
      queue_family_ = i;
      timestamp_valid_bits_ = families[i].timestampValidBits;
      found = true;
    }
  }
  if (!found) return fail(ErrorKind::Device, who + " has no queue family with graphics and compute");
  return ok_status();
}

// Extensions and features: the device with what the techniques use, where it has it, and its
// queue.
Status Context::create_device(const std::string& who) {
  (void)who;  // vulkan_device_requirements names the device itself
  auto req = vulkan_device_requirements(instance_, physical_, !api_1_3_);
  if (!req) return req.error();
  large_points_ = req->features.features.largePoints == VK_TRUE;
  image_float_atomic_add_ = req->atomic_float_present;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = req->chain();
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(req->device_extensions.size());
  dci.ppEnabledExtensionNames = req->device_extensions.data();
  VK_CHECK(vkCreateDevice(physical_, &dci, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  return ok_status();
}

// The app's objects (mrgi/vulkan_device.h), checked for what mrgi needs, in place of an
// instance and a device of mrgi's own.
Status Context::init_app_device(const DeviceSettings& settings) {
  const AppVulkanDevice& app = *settings.app_device;
  if (settings.validate)
    return fail(ErrorKind::BadUsage, "DeviceSettings::validate with DeviceSettings::app_device: validation layers "
                                     "belong to the app's instance (enable VK_LAYER_KHRONOS_validation there)");
  auto enabled = check_app_device(app, settings.vulkan_1_2);
  if (!enabled) return enabled.error();
  owns_device_ = false;
  instance_ = app.instance;
  physical_ = app.physical_device;
  device_ = app.device;
  queue_ = app.queue;
  queue_family_ = app.queue_family;
  lock_queue_ = app.lock_queue;
  unlock_queue_ = app.unlock_queue;
  api_1_3_ = enabled->api_1_3;
  large_points_ = enabled->large_points;
  image_float_atomic_add_ = enabled->image_float_atomic_add;
  auto pds = physical_devices(instance_);
  if (!pds) return pds.error();
  const std::vector<DeviceInfo> devices = describe_all(*pds);
  for (size_t i = 0; i < pds->size(); ++i)
    if ((*pds)[i] == physical_) info_ = devices[i];
  info_.selected = true;
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_properties_);
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, families.data());
  timestamp_valid_bits_ = families[queue_family_].timestampValidBits;
  const std::string who = "the app's device '" + info_.name + "'";
  MRGI_TRY(load_device_functions(who));
  MRGI_TRY(create_upload_pool());
  MRGI_TRY(create_samplers());
  return ok_status();
}

VkResult Context::queue_submit2(const VkSubmitInfo2& submit, VkFence fence) const {
  if (lock_queue_) lock_queue_();
  const VkResult r = fn_.queue_submit2(queue_, 1, &submit, fence);
  if (unlock_queue_) unlock_queue_();
  return r;
}

VkResult Context::queue_submit(const VkSubmitInfo& submit, VkFence fence) const {
  if (lock_queue_) lock_queue_();
  const VkResult r = vkQueueSubmit(queue_, 1, &submit, fence);
  if (unlock_queue_) unlock_queue_();
  return r;
}

// The entry points that are core in 1.3 and extensions in 1.2, and push descriptors.
Status Context::load_device_functions(const std::string& who) {
  const bool is13 = api_1_3_;
  fn_.cmd_pipeline_barrier2 = load_device_fn<PFN_vkCmdPipelineBarrier2>(
      device_, is13 ? "vkCmdPipelineBarrier2" : "vkCmdPipelineBarrier2KHR", nullptr);
  fn_.cmd_write_timestamp2 = load_device_fn<PFN_vkCmdWriteTimestamp2>(
      device_, is13 ? "vkCmdWriteTimestamp2" : "vkCmdWriteTimestamp2KHR", nullptr);
  fn_.queue_submit2 = load_device_fn<PFN_vkQueueSubmit2>(device_, is13 ? "vkQueueSubmit2" : "vkQueueSubmit2KHR", nullptr);
  fn_.cmd_begin_rendering = load_device_fn<PFN_vkCmdBeginRendering>(
      device_, is13 ? "vkCmdBeginRendering" : "vkCmdBeginRenderingKHR", nullptr);
  fn_.cmd_end_rendering = load_device_fn<PFN_vkCmdEndRendering>(
      device_, is13 ? "vkCmdEndRendering" : "vkCmdEndRenderingKHR", nullptr);
  fn_.cmd_push_descriptor_set = load_device_fn<PFN_vkCmdPushDescriptorSetKHR>(device_, "vkCmdPushDescriptorSetKHR", nullptr);
  if (!fn_.cmd_pipeline_barrier2 || !fn_.cmd_write_timestamp2 || !fn_.queue_submit2 ||
      !fn_.cmd_begin_rendering || !fn_.cmd_end_rendering || !fn_.cmd_push_descriptor_set)
    return fail(ErrorKind::Device, who + ": a required device entry point (sync2, dynamic rendering or "
                                         "push descriptors) could not be loaded");
  return ok_status();
}

Status Context::create_upload_pool() {
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pci.queueFamilyIndex = queue_family_;
  VK_CHECK(vkCreateCommandPool(device_, &pci, nullptr, &upload_pool_));
  return ok_status();
}

// StandardSamplers: linear clamp and repeat, nearest clamp, the shadow maps' compare.
Status Context::create_samplers() {
  VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
  sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sci.maxLod = VK_LOD_CLAMP_NONE;
  VK_CHECK(vkCreateSampler(device_, &sci, nullptr, &samplers_.linear_clamp));
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  VK_CHECK(vkCreateSampler(device_, &sci, nullptr, &samplers_.linear_repeat));
  sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
  sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VK_CHECK(vkCreateSampler(device_, &sci, nullptr, &samplers_.nearest_clamp));
  sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
  sci.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
  sci.compareEnable = VK_TRUE;
  sci.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  VK_CHECK(vkCreateSampler(device_, &sci, nullptr, &samplers_.shadow_compare));
  return ok_status();
}

Context::~Context() {
  if (device_) {
    // An app's device may be busy with the app's own work: mrgi's work has completed by now (the
    // frame graph waited for its fences; start-up submissions wait for theirs).
    if (owns_device_) vkDeviceWaitIdle(device_);
    for (VkSampler s : {samplers_.linear_clamp, samplers_.nearest_clamp, samplers_.linear_repeat,
                        samplers_.shadow_compare})
      if (s) vkDestroySampler(device_, s, nullptr);
    if (upload_pool_) vkDestroyCommandPool(device_, upload_pool_, nullptr);
    if (owns_device_) vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_ && owns_device_) vkDestroyInstance(instance_, nullptr);
}

void Context::record_validation_message(std::string message) {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  messages_.push_back(std::move(message));
}
size_t Context::validation_message_count() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return messages_.size();
}
std::vector<std::string> Context::validation_messages() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return messages_;
}
void Context::clear_validation_messages() {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  messages_.clear();
}

void Context::set_name(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (!set_object_name_ || name.empty()) return;
  VkDebugUtilsObjectNameInfoEXT ni{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  ni.objectType = type;
  ni.objectHandle = handle;
  ni.pObjectName = name.c_str();
  set_object_name_(device_, &ni);
}

}  // namespace mrgi::gpu

namespace mrgi {

Expected<std::vector<DeviceInfo>> list_devices(const DeviceSettings& settings) {
  auto instance = gpu::create_instance_for_listing(settings.validate);
  if (!instance) return instance.error();
  auto pds = gpu::physical_devices_for_listing(*instance);
  std::vector<DeviceInfo> devices;
  if (pds) devices = gpu::describe_all_devices(*pds);
  vkDestroyInstance(*instance, nullptr);
  if (!pds) return pds.error();
  auto chosen = gpu::select_device_index(devices, gpu::effective_device_selector(settings));
  if (!chosen) return chosen.error();
  devices[*chosen].selected = true;
  return devices;
}

}  // namespace mrgi
