// mrgi/vulkan_device.h: what mrgi enables on a device, and the check of an app's device against it.
#include "gpu/device_requirements.h"

#include <algorithm>
#include <cstring>
#include <vector>

namespace mrgi {
namespace {

std::string version_text(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v));
}

// The features mrgi enables where the physical device has them, by structure: X(member). One
// list for filling the requirements and for checking an app's device. largePoints is not here:
// it is optional (mrgi draws 1-pixel points without it; gpu::Context::max_point_size).
#define MRGI_CORE_FEATURES(X)                                                                          \
  X(fragmentStoresAndAtomics) X(vertexPipelineStoresAndAtomics) X(shaderStorageImageWriteWithoutFormat) \
  X(shaderStorageImageReadWithoutFormat) X(depthClamp) X(depthBiasClamp) X(independentBlend)            \
  X(multiDrawIndirect) X(drawIndirectFirstInstance) X(imageCubeArray) X(shaderInt16) X(samplerAnisotropy)
#define MRGI_VULKAN12_FEATURES(X)                                                         \
  X(scalarBlockLayout) X(hostQueryReset) X(shaderFloat16) X(storageBuffer8BitAccess) \
  X(uniformAndStorageBuffer8BitAccess) X(shaderInt8)
#define MRGI_VULKAN11_FEATURES(X) X(shaderDrawParameters) X(storageBuffer16BitAccess)

bool has_graphics_compute_family(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  return std::any_of(families.begin(), families.end(), [&](const auto& f) { return (f.queueFlags & need) == need; });
}

}  // namespace

VkPhysicalDeviceFeatures2* VulkanDeviceRequirements::chain(void* next) {
  features.pNext = &vulkan11;
  vulkan11.pNext = &vulkan12;
  VkBaseOutStructure* tail = reinterpret_cast<VkBaseOutStructure*>(&vulkan12);
  auto link = [&](void* s) {
    tail->pNext = static_cast<VkBaseOutStructure*>(s);
    tail = static_cast<VkBaseOutStructure*>(s);
  };
  if (api_version >= VK_API_VERSION_1_3) {
    link(&vulkan13);
  } else {
    link(&synchronization2);
    link(&dynamic_rendering);
  }
  if (atomic_float_present) link(&atomic_float);
  tail->pNext = static_cast<VkBaseOutStructure*>(next);
  return &features;
}

Expected<VulkanDeviceRequirements> vulkan_device_requirements(VkInstance instance, VkPhysicalDevice physical,
                                                              bool vulkan_1_2) {
  if (instance == VK_NULL_HANDLE || physical == VK_NULL_HANDLE)
    return fail(ErrorKind::BadUsage, "vulkan_device_requirements: a null instance or physical device");
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(physical, &props);
  const std::string who = std::string("device '") + props.deviceName + "'";
  if (props.apiVersion < VK_API_VERSION_1_2)
    return fail(ErrorKind::Device, who + " has Vulkan " + version_text(props.apiVersion) + "; mrgi needs 1.2 or later");
  if (!has_graphics_compute_family(physical))
    return fail(ErrorKind::Device, who + " has no queue family with graphics and compute");
  VulkanDeviceRequirements r;
  const bool api13 = props.apiVersion >= VK_API_VERSION_1_3 && !vulkan_1_2;
  r.api_version = api13 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2;
  auto require = [&](const char* ext) -> Status {
    if (!gpu::device_has_extension(physical, ext))
      return fail(ErrorKind::Device, who + " lacks " + ext + ", which mrgi requires");
    r.device_extensions.push_back(ext);
    return ok_status();
  };
  MRGI_TRY(require(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME));
  if (!api13) {
    MRGI_TRY(require(VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME));
    MRGI_TRY(require(VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME));
  }
  // What the device has.
  VkPhysicalDeviceSynchronization2Features sync2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  VkPhysicalDeviceDynamicRenderingFeatures dynr{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  const bool has_atomic = gpu::device_has_extension(physical, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
  VkPhysicalDeviceFeatures2 have{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  have.pNext = &sync2;
  sync2.pNext = &dynr;
  dynr.pNext = &f12;
  f12.pNext = &f11;
  if (has_atomic) f11.pNext = &atomic;
  vkGetPhysicalDeviceFeatures2(physical, &have);
  if (!sync2.synchronization2) return fail(ErrorKind::Device, who + " lacks the synchronization2 feature");
  if (!dynr.dynamicRendering) return fail(ErrorKind::Device, who + " lacks the dynamicRendering feature");
  // What mrgi enables of it.
#define MRGI_TAKE_CORE(m) r.features.features.m = have.features.m;
  MRGI_CORE_FEATURES(MRGI_TAKE_CORE)
#undef MRGI_TAKE_CORE
  r.features.features.largePoints = have.features.largePoints;
#define MRGI_TAKE_12(m) r.vulkan12.m = f12.m;
  MRGI_VULKAN12_FEATURES(MRGI_TAKE_12)
#undef MRGI_TAKE_12
#define MRGI_TAKE_11(m) r.vulkan11.m = f11.m;
  MRGI_VULKAN11_FEATURES(MRGI_TAKE_11)
#undef MRGI_TAKE_11
  if (api13) {
    r.vulkan13.synchronization2 = VK_TRUE;
    r.vulkan13.dynamicRendering = VK_TRUE;
  } else {
    r.synchronization2.synchronization2 = VK_TRUE;
    r.dynamic_rendering.dynamicRendering = VK_TRUE;
  }
  if (has_atomic && atomic.shaderImageFloat32AtomicAdd) {
    r.atomic_float.shaderImageFloat32Atomics = VK_TRUE;
    r.atomic_float.shaderImageFloat32AtomicAdd = VK_TRUE;
    r.atomic_float_present = true;
    r.device_extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
  }
  return r;
}

namespace gpu {

bool device_has_extension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  if (vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> exts(n);
  if (vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data()) != VK_SUCCESS) return false;
  for (const auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

namespace {

// The feature structures an app may have enabled mrgi's features through: the Vulkan 1.x
// aggregates or the older per-feature structures, merged.
struct EnabledFeatures {
  VkPhysicalDeviceFeatures core{};
  VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  bool synchronization2 = false, dynamic_rendering = false, image_float_atomic_add = false;
};

EnabledFeatures read_chain(const VkPhysicalDeviceFeatures2* head) {
  EnabledFeatures e;
  auto on = [](VkBool32& into, VkBool32 v) { into = into || v; };
  for (auto* s = reinterpret_cast<const VkBaseInStructure*>(head); s; s = s->pNext) {
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2:
        e.core = reinterpret_cast<const VkPhysicalDeviceFeatures2*>(s)->features;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES: {
        const auto* f = reinterpret_cast<const VkPhysicalDeviceVulkan11Features*>(s);
#define MRGI_READ_11(m) on(e.v11.m, f->m);
        MRGI_VULKAN11_FEATURES(MRGI_READ_11)
#undef MRGI_READ_11
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES: {
        const auto* f = reinterpret_cast<const VkPhysicalDeviceVulkan12Features*>(s);
#define MRGI_READ_12(m) on(e.v12.m, f->m);
        MRGI_VULKAN12_FEATURES(MRGI_READ_12)
#undef MRGI_READ_12
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES: {
        const auto* f = reinterpret_cast<const VkPhysicalDeviceVulkan13Features*>(s);
        e.synchronization2 = e.synchronization2 || f->synchronization2;
        e.dynamic_rendering = e.dynamic_rendering || f->dynamicRendering;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES:
        e.synchronization2 = e.synchronization2 || reinterpret_cast<const VkPhysicalDeviceSynchronization2Features*>(s)->synchronization2;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES:
        e.dynamic_rendering = e.dynamic_rendering || reinterpret_cast<const VkPhysicalDeviceDynamicRenderingFeatures*>(s)->dynamicRendering;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT:
        e.image_float_atomic_add = reinterpret_cast<const VkPhysicalDeviceShaderAtomicFloatFeaturesEXT*>(s)->shaderImageFloat32AtomicAdd;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES:
        on(e.v11.storageBuffer16BitAccess, reinterpret_cast<const VkPhysicalDevice16BitStorageFeatures*>(s)->storageBuffer16BitAccess);
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_DRAW_PARAMETERS_FEATURES:
        on(e.v11.shaderDrawParameters, reinterpret_cast<const VkPhysicalDeviceShaderDrawParametersFeatures*>(s)->shaderDrawParameters);
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES: {
        const auto* f = reinterpret_cast<const VkPhysicalDeviceShaderFloat16Int8Features*>(s);
        on(e.v12.shaderFloat16, f->shaderFloat16);
        on(e.v12.shaderInt8, f->shaderInt8);
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_8BIT_STORAGE_FEATURES: {
        const auto* f = reinterpret_cast<const VkPhysicalDevice8BitStorageFeatures*>(s);
        on(e.v12.storageBuffer8BitAccess, f->storageBuffer8BitAccess);
        on(e.v12.uniformAndStorageBuffer8BitAccess, f->uniformAndStorageBuffer8BitAccess);
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES:
        on(e.v12.scalarBlockLayout, reinterpret_cast<const VkPhysicalDeviceScalarBlockLayoutFeatures*>(s)->scalarBlockLayout);
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_HOST_QUERY_RESET_FEATURES:
        on(e.v12.hostQueryReset, reinterpret_cast<const VkPhysicalDeviceHostQueryResetFeatures*>(s)->hostQueryReset);
        break;
      default:
        break;
    }
  }
  return e;
}

}  // namespace

Expected<AppDeviceEnabled> check_app_device(const AppVulkanDevice& app, bool vulkan_1_2) {
  const std::string field = "DeviceSettings::app_device";
  if (!app.instance || !app.physical_device || !app.device || !app.queue)
    return fail(ErrorKind::BadUsage, field + ": instance, physical_device, device and queue must all be set");
  if (bool(app.lock_queue) != bool(app.unlock_queue))
    return fail(ErrorKind::BadUsage, field + ": lock_queue and unlock_queue go together (both or neither)");
  if (app.api_version < VK_API_VERSION_1_2)
    return fail(ErrorKind::BadUsage, field + ".api_version " + version_text(app.api_version) +
                                         ": mrgi needs an instance created for Vulkan 1.2 or later");
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(app.instance, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(app.instance, &n, pds.data());
  if (std::find(pds.begin(), pds.end(), app.physical_device) == pds.end())
    return fail(ErrorKind::BadUsage, field + ".physical_device is not one of the instance's physical devices");
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(app.physical_device, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(app.physical_device, &nq, families.data());
  const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  if (app.queue_family >= nq || (families[app.queue_family].queueFlags & need) != need)
    return fail(ErrorKind::BadUsage, field + ".queue_family " + std::to_string(app.queue_family) +
                                         ": must be a family of the device with graphics and compute");

  auto req = vulkan_device_requirements(app.instance, app.physical_device,
                                        vulkan_1_2 || app.api_version < VK_API_VERSION_1_3);
  if (!req) return req.error();
  std::vector<std::string> missing;
  auto enabled_ext = [&](const char* name) {
    return std::find(app.enabled_extensions.begin(), app.enabled_extensions.end(), name) != app.enabled_extensions.end();
  };
  for (const char* ext : req->device_extensions)
    if (std::strcmp(ext, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME) != 0 && !enabled_ext(ext)) missing.push_back(ext);
  const EnabledFeatures en = read_chain(app.enabled_features);
  const bool api13 = req->api_version >= VK_API_VERSION_1_3;
  if (!en.synchronization2)
    missing.push_back(api13 ? "VkPhysicalDeviceVulkan13Features::synchronization2"
                            : "VkPhysicalDeviceSynchronization2Features::synchronization2");
  if (!en.dynamic_rendering)
    missing.push_back(api13 ? "VkPhysicalDeviceVulkan13Features::dynamicRendering"
                            : "VkPhysicalDeviceDynamicRenderingFeatures::dynamicRendering");
#define MRGI_CHECK(structure, want, have, m) \
  if (want.m && !have.m) missing.push_back(std::string(structure "::") + #m);
#define MRGI_CHECK_CORE(m) MRGI_CHECK("VkPhysicalDeviceFeatures", req->features.features, en.core, m)
  MRGI_CORE_FEATURES(MRGI_CHECK_CORE)
#define MRGI_CHECK_12(m) MRGI_CHECK("VkPhysicalDeviceVulkan12Features", req->vulkan12, en.v12, m)
  MRGI_VULKAN12_FEATURES(MRGI_CHECK_12)
#define MRGI_CHECK_11(m) MRGI_CHECK("VkPhysicalDeviceVulkan11Features", req->vulkan11, en.v11, m)
  MRGI_VULKAN11_FEATURES(MRGI_CHECK_11)
#undef MRGI_CHECK_11
#undef MRGI_CHECK_12
#undef MRGI_CHECK_CORE
#undef MRGI_CHECK
  if (!missing.empty()) {
    std::string list;
    for (const std::string& m : missing) list += (list.empty() ? "" : ", ") + m;
    return fail(ErrorKind::BadUsage, field + ": the app's device was created without what mrgi needs on it: " + list +
                                         " (mrgi::vulkan_device_requirements lists what to enable)");
  }
  AppDeviceEnabled out;
  out.api_1_3 = api13;
  out.large_points = en.core.largePoints == VK_TRUE;
  out.image_float_atomic_add = en.image_float_atomic_add && enabled_ext(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
  return out;
}

}  // namespace gpu
}  // namespace mrgi
