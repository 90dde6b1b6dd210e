#include "gpu/context.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

#include "gpu/vk_check.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mrgi::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint64_t kUploadTimeoutNs = 30ull * 1000 * 1000 * 1000;

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

bool device_has_extension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  if (vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> exts(n);
  if (vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data()) != VK_SUCCESS) return false;
  for (const auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
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
  for (const auto& d : devices)
    if (lower(d.name).find(want) != std::string::npos) return d.index;
  return fail(ErrorKind::BadUsage, "device selector '" + selector +
                                       "' matches no device name (use an index or a name substring):" +
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
  const std::string who = "device " + std::to_string(info_.index) + " '" + info_.name + "'";
  if (properties_.apiVersion < VK_API_VERSION_1_2)
    return fail(ErrorKind::Device, who + " has Vulkan " + version_string(properties_.apiVersion) +
                                       "; mrgi needs 1.2 or later");
  // The 1.3 entry points only where both the device and the settings allow them.
  const bool is13 = properties_.apiVersion >= VK_API_VERSION_1_3 && !settings.vulkan_1_2;
  api_1_3_ = is13;

  // Queue: the first family with graphics and compute.
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

  // Extensions and features. sync2 and dynamic rendering are core in 1.3 and extensions in 1.2.
  std::vector<const char*> extensions;
  auto require = [&](const char* ext) -> Status {
    if (!device_has_extension(physical_, ext))
      return fail(ErrorKind::Device, who + " lacks " + ext + ", which mrgi requires");
    extensions.push_back(ext);
    return ok_status();
  };
  MRGI_TRY(require(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME));
  if (!is13) {
    MRGI_TRY(require(VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME));
    MRGI_TRY(require(VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME));
  }
  VkPhysicalDeviceSynchronization2Features sync2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  VkPhysicalDeviceDynamicRenderingFeatures dynr{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  // Float atomics (optional): the light propagation volumes sum VPLs into cells with
  // imageAtomicAdd on R32F texel buffers (gi/lpv_inject.comp). Lavapipe and desktop GPUs have it.
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic_float{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  const bool has_atomic_float = device_has_extension(physical_, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
  VkPhysicalDeviceFeatures2 have{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  have.pNext = &sync2;
  sync2.pNext = &dynr;
  dynr.pNext = &f12;
  f12.pNext = &f11;
  if (has_atomic_float) f11.pNext = &atomic_float;
  vkGetPhysicalDeviceFeatures2(physical_, &have);
  if (!sync2.synchronization2) return fail(ErrorKind::Device, who + " lacks the synchronization2 feature");
  if (!dynr.dynamicRendering) return fail(ErrorKind::Device, who + " lacks the dynamicRendering feature");

  // Enable only what the techniques use, where the device has it.
  VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  const VkPhysicalDeviceFeatures& h = have.features;
  VkPhysicalDeviceFeatures& w = want.features;
  w.fragmentStoresAndAtomics = h.fragmentStoresAndAtomics;
  w.vertexPipelineStoresAndAtomics = h.vertexPipelineStoresAndAtomics;
  w.shaderStorageImageWriteWithoutFormat = h.shaderStorageImageWriteWithoutFormat;
  w.shaderStorageImageReadWithoutFormat = h.shaderStorageImageReadWithoutFormat;
  w.largePoints = h.largePoints;
  w.depthClamp = h.depthClamp;
  w.depthBiasClamp = h.depthBiasClamp;
  w.independentBlend = h.independentBlend;
  w.multiDrawIndirect = h.multiDrawIndirect;
  w.drawIndirectFirstInstance = h.drawIndirectFirstInstance;
  w.imageCubeArray = h.imageCubeArray;
  w.shaderInt16 = h.shaderInt16;
  w.samplerAnisotropy = h.samplerAnisotropy;
  VkPhysicalDeviceSynchronization2Features sync2_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  sync2_on.synchronization2 = VK_TRUE;
  VkPhysicalDeviceDynamicRenderingFeatures dynr_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
  dynr_on.dynamicRendering = VK_TRUE;
  VkPhysicalDeviceVulkan12Features f12_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12_on.scalarBlockLayout = f12.scalarBlockLayout;
  f12_on.hostQueryReset = f12.hostQueryReset;
  f12_on.shaderFloat16 = f12.shaderFloat16;
  f12_on.storageBuffer8BitAccess = f12.storageBuffer8BitAccess;
  f12_on.uniformAndStorageBuffer8BitAccess = f12.uniformAndStorageBuffer8BitAccess;
  f12_on.shaderInt8 = f12.shaderInt8;
  VkPhysicalDeviceVulkan11Features f11_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  f11_on.shaderDrawParameters = f11.shaderDrawParameters;
  f11_on.storageBuffer16BitAccess = f11.storageBuffer16BitAccess;
  want.pNext = &sync2_on;
  sync2_on.pNext = &dynr_on;
  dynr_on.pNext = &f12_on;
  f12_on.pNext = &f11_on;
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic_float_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  if (has_atomic_float && atomic_float.shaderImageFloat32AtomicAdd) {
    atomic_float_on.shaderImageFloat32Atomics = VK_TRUE;
    atomic_float_on.shaderImageFloat32AtomicAdd = VK_TRUE;
    f11_on.pNext = &atomic_float_on;
    extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
    image_float_atomic_add_ = true;
  }

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &want;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(extensions.size());
  dci.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(vkCreateDevice(physical_, &dci, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

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

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pci.queueFamilyIndex = queue_family_;
  VK_CHECK(vkCreateCommandPool(device_, &pci, nullptr, &upload_pool_));

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
    vkDeviceWaitIdle(device_);
    for (VkSampler s : {samplers_.linear_clamp, samplers_.nearest_clamp, samplers_.linear_repeat,
                        samplers_.shadow_compare})
      if (s) vkDestroySampler(device_, s, nullptr);
    if (upload_pool_) vkDestroyCommandPool(device_, upload_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
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

Expected<VkDeviceMemory> Context::allocate(const VkMemoryRequirements& req, MemoryUsage usage, bool* coherent) {
  VkMemoryPropertyFlags need = 0, prefer = 0;
  switch (usage) {
    case MemoryUsage::DeviceLocal: need = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT; break;
    case MemoryUsage::Upload:
      need = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
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
    VK_CHECK(vkQueueSubmit(queue_, 1, &si, fence));
    const VkResult w = vkWaitForFences(device_, 1, &fence, VK_TRUE, kUploadTimeoutNs);
    if (w == VK_TIMEOUT) return fail(ErrorKind::Timeout, "start-up upload did not finish within 30 s");
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
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_NONE;
    b.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = dst.image;
    b.subresourceRange = {dst.aspect, 0, dst.mip_levels, 0, dst.layers};
    VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    di.imageMemoryBarrierCount = 1;
    di.pImageMemoryBarriers = &b;
    fn_.cmd_pipeline_barrier2(cmd, &di);
    VkBufferImageCopy region{};
    region.imageSubresource = {dst.aspect, 0, 0, dst.layers};
    region.imageExtent = {dst.extent.width, dst.extent.height, dst.depth};
    vkCmdCopyBufferToImage(cmd, staging->buffer, dst.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = final_layout;
    fn_.cmd_pipeline_barrier2(cmd, &di);
  });
  destroy(*staging);
  return s;
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
