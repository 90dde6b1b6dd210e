// The live view (live_view.h): GLFW's window, a Vulkan instance and device of the view's own with a
// swapchain and mrgi's requirements, one staging copy of each composite into the presented image.
#include "live_view.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#include <GLFW/glfw3native.h>
#include <X11/Xutil.h>
// Xlib's own: mrgi's Status and its X calls' return type would collide.
#undef Status

namespace mrgi::tool {
namespace {

Status vk_fail(const char* what, VkResult r) {
  return fail(ErrorKind::Device, std::string("live view: ") + what + " failed (VkResult " + std::to_string(int(r)) + ")");
}
#define VIEW_CHECK(call)                          \
  do {                                            \
    const VkResult r_ = (call);                   \
    if (r_ != VK_SUCCESS) return vk_fail(#call, r_); \
  } while (0)

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

class GlfwView final : public LiveView {
 public:
  ~GlfwView() override {
    if (device_) {
      vkDeviceWaitIdle(device_);  // the view is the app: its own device, every queue its own
      destroy_swapchain();
      if (staging_) vkDestroyBuffer(device_, staging_, nullptr);
      if (staging_memory_) vkFreeMemory(device_, staging_memory_, nullptr);
      if (acquired_) vkDestroySemaphore(device_, acquired_, nullptr);
      if (fence_) vkDestroyFence(device_, fence_, nullptr);
      if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
      vkDestroyDevice(device_, nullptr);
    }
    if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
    if (instance_) vkDestroyInstance(instance_, nullptr);
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
  }

  Status init(const std::string& title, int width, int height, const std::string& selector) {
    title_ = title;
    width_ = width;
    height_ = height;
    if (!glfwInit())
      return fail(ErrorKind::Device, "live view: no display to open a window on (GLFW could not start: is $DISPLAY set "
                                     "and an X server running? Under no display: xvfb-run)");
    if (!glfwVulkanSupported()) return fail(ErrorKind::Device, "live view: GLFW finds no Vulkan loader");
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) return fail(ErrorKind::Device, "live view: the window could not be created");
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, &GlfwView::on_key);
    MRGI_TRY(create_instance());
    VIEW_CHECK(glfwCreateWindowSurface(instance_, window_, nullptr, &surface_));
    MRGI_TRY(pick_device(selector));
    MRGI_TRY(create_device());
    return create_swapchain();
  }

  const AppVulkanDevice& device() const override { return app_; }

  Status show(const ImageRGBA8& composite, const ImageRGB8& camera, const std::string& status) override {
    const int w = composite.width * (side_by_side_ ? 2 : 1), h = composite.height;
    if (w != width_ || h != height_) {
      width_ = w;
      height_ = h;
      glfwSetWindowSize(window_, w, h);
      MRGI_TRY(recreate_swapchain());
    }
    glfwSetWindowTitle(window_, (show_stats_ ? title_ + " | " + status : title_).c_str());
    VIEW_CHECK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
    // The swapchain's byte order (B8G8R8A8 or R8G8B8A8, UNORM: the composite's sRGB-encoded bytes
    // go to the screen as they are).
    const bool bgr = format_ == VK_FORMAT_B8G8R8A8_UNORM;
    auto* dst = static_cast<uint8_t*>(mapped_);
    const int x_composite = side_by_side_ ? composite.width : 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t* d = dst + (size_t(y) * size_t(w) + size_t(x)) * 4;
        const bool left = x < x_composite;
        const uint8_t* s = left ? camera.at(std::min(x, camera.width - 1), std::min(y, camera.height - 1))
                                : composite.at(x - x_composite, y);
        d[0] = bgr ? s[2] : s[0];
        d[1] = s[1];
        d[2] = bgr ? s[0] : s[2];
        d[3] = 255;
      }
    uint32_t index = 0;
    VkResult r = vkAcquireNextImageKHR(device_, swapchain_, UINT64_MAX, acquired_, VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
      MRGI_TRY(recreate_swapchain());
      return show(composite, camera, status);
    }
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) return vk_fail("vkAcquireNextImageKHR", r);
    VIEW_CHECK(vkResetFences(device_, 1, &fence_));
    MRGI_TRY(record_copy(images_[index]));
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &acquired_;
    si.pWaitDstStageMask = &wait_stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd_;
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &rendered_[index];
    VIEW_CHECK(vkQueueSubmit(queue_, 1, &si, fence_));
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &rendered_[index];
    pi.swapchainCount = 1;
    pi.pSwapchains = &swapchain_;
    pi.pImageIndices = &index;
    r = vkQueuePresentKHR(queue_, &pi);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return recreate_swapchain();
    if (r != VK_SUCCESS) return vk_fail("vkQueuePresentKHR", r);
    return ok_status();
  }

  ViewRequests poll() override {
    glfwPollEvents();
    while (paused_ && !glfwWindowShouldClose(window_) && !requests_.quit) glfwWaitEventsTimeout(0.1);
    ViewRequests r = requests_;
    r.quit = r.quit || glfwWindowShouldClose(window_);
    requests_ = ViewRequests{};
    return r;
  }

  void hold() override {
    while (!glfwWindowShouldClose(window_) && !requests_.quit) glfwWaitEventsTimeout(0.1);
  }

  Expected<ImageRGB8> screenshot() override {
    vkDeviceWaitIdle(device_);
    // The present reaches the X server through the driver's own connection: give it time, then
    // read what the server holds for the window.
    for (int i = 0; i < 10; ++i) {
      glfwPollEvents();
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
    }
    Display* display = glfwGetX11Display();
    const Window window = glfwGetX11Window(window_);
    XSync(display, False);
    XImage* shot = XGetImage(display, window, 0, 0, unsigned(width_), unsigned(height_), AllPlanes, ZPixmap);
    if (!shot) return fail(ErrorKind::Device, "live view: XGetImage of the window failed");
    if (!shot->red_mask || !shot->green_mask || !shot->blue_mask) {
      XDestroyImage(shot);
      return fail(ErrorKind::Device, "live view: the window's visual has no RGB masks (not TrueColor): no screenshot");
    }
    ImageRGB8 out(width_, height_);
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x) {
        const unsigned long p = XGetPixel(shot, x, y);
        uint8_t* d = out.at(x, y);
        d[0] = uint8_t((p & shot->red_mask) >> __builtin_ctzl(shot->red_mask));
        d[1] = uint8_t((p & shot->green_mask) >> __builtin_ctzl(shot->green_mask));
        d[2] = uint8_t((p & shot->blue_mask) >> __builtin_ctzl(shot->blue_mask));
      }
    XDestroyImage(shot);
    return out;
  }

 private:
  static void on_key(GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS) return;
    auto* v = static_cast<GlfwView*>(glfwGetWindowUserPointer(window));
    switch (key) {
      case GLFW_KEY_T: v->requests_.next_technique = true; break;
      case GLFW_KEY_LEFT_BRACKET: v->requests_.level_step = 1; break;
      case GLFW_KEY_RIGHT_BRACKET: v->requests_.level_step = -1; break;
      case GLFW_KEY_S: v->side_by_side_ = !v->side_by_side_; break;
      case GLFW_KEY_I: v->show_stats_ = !v->show_stats_; break;
      case GLFW_KEY_SPACE: v->paused_ = !v->paused_; break;
      case GLFW_KEY_Q:
      case GLFW_KEY_ESCAPE: v->requests_.quit = true; break;
      default: break;
    }
  }

  Status create_instance() {
    uint32_t n = 0;
    const char** required = glfwGetRequiredInstanceExtensions(&n);
    if (!required) return fail(ErrorKind::Device, "live view: no Vulkan surface support for the window system");
    VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    ai.pApplicationName = "mrgi view";
    ai.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &ai;
    ici.enabledExtensionCount = n;
    ici.ppEnabledExtensionNames = required;
    VIEW_CHECK(vkCreateInstance(&ici, nullptr, &instance_));
    app_.api_version = ai.apiVersion;
    return ok_status();
  }

  // The first device the selector names (DeviceSettings::device's rules, by name or kind) that
  // has a family with graphics, compute and presentation to the window.
  Status pick_device(const std::string& selector) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance_, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance_, &n, devices.data());
    const std::string want = lower(selector);
    auto named = [&](VkPhysicalDevice d, int index) {
      VkPhysicalDeviceProperties p{};
      vkGetPhysicalDeviceProperties(d, &p);
      const std::string name = lower(p.deviceName);
      if (want.empty() || want == "cpu" || want == "lavapipe" || want == "llvmpipe")
        return p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
      if (want == "gpu") return p.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
      if (std::all_of(want.begin(), want.end(), [](unsigned char c) { return std::isdigit(c); }))
        return std::to_string(index) == want;
      return name.find(want) != std::string::npos;
    };
    for (int i = 0; i < int(devices.size()) && !physical_; ++i) {
      if (!named(devices[size_t(i)], i)) continue;
      uint32_t nq = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(devices[size_t(i)], &nq, nullptr);
      std::vector<VkQueueFamilyProperties> families(nq);
      vkGetPhysicalDeviceQueueFamilyProperties(devices[size_t(i)], &nq, families.data());
      for (uint32_t f = 0; f < nq; ++f) {
        VkBool32 present = VK_FALSE;
        vkGetPhysicalDeviceSurfaceSupportKHR(devices[size_t(i)], f, surface_, &present);
        const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        if (present && (families[f].queueFlags & need) == need) {
          physical_ = devices[size_t(i)];
          family_ = f;
          break;
        }
      }
    }
    if (!physical_)
      return fail(ErrorKind::Device, "live view: no Vulkan device matching '" + (selector.empty() ? "lavapipe" : selector) +
                                         "' can present to the window");
    return ok_status();
  }

  // mrgi's requirements plus the swapchain; the queue shared with the runtime (one thread).
  Status create_device() {
    auto needs = vulkan_device_requirements(instance_, physical_);
    if (!needs) return needs.error();
    needs_ = std::move(*needs);
    std::vector<const char*> extensions = needs_.device_extensions;
    extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = needs_.chain();
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = uint32_t(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
    VIEW_CHECK(vkCreateDevice(physical_, &dci, nullptr, &device_));
    vkGetDeviceQueue(device_, family_, 0, &queue_);
    app_.instance = instance_;
    app_.physical_device = physical_;
    app_.device = device_;
    app_.queue = queue_;
    app_.queue_family = family_;
    for (const char* e : extensions) app_.enabled_extensions.push_back(e);
    app_.enabled_features = &needs_.features;
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = family_;
    VIEW_CHECK(vkCreateCommandPool(device_, &pci, nullptr, &pool_));
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VIEW_CHECK(vkAllocateCommandBuffers(device_, &ai, &cmd_));
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VIEW_CHECK(vkCreateSemaphore(device_, &sci, nullptr, &acquired_));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VIEW_CHECK(vkCreateFence(device_, &fci, nullptr, &fence_));
    return ok_status();
  }

  Status create_swapchain() {
    VkSurfaceCapabilitiesKHR caps{};
    // After a resize the window system reports the new size once it has applied it.
    for (int i = 0; i < 100; ++i) {
      VIEW_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_, surface_, &caps));
      if (caps.currentExtent.width == 0xFFFFFFFFu ||
          (caps.currentExtent.width == uint32_t(width_) && caps.currentExtent.height == uint32_t(height_)))
        break;
      glfwWaitEventsTimeout(0.01);
    }
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
      return fail(ErrorKind::Device, "live view: the window's swapchain images cannot be copied into");
    uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &n, formats.data());
    format_ = VK_FORMAT_UNDEFINED;
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
        format_ = f.format;
        color_space_ = f.colorSpace;
        break;
      }
    if (format_ == VK_FORMAT_UNDEFINED)
      return fail(ErrorKind::Device, "live view: the window offers no 8-bit UNORM RGBA or BGRA format");
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.surface = surface_;
    ci.minImageCount = std::max(2u, caps.minImageCount);
    if (caps.maxImageCount) ci.minImageCount = std::min(ci.minImageCount, caps.maxImageCount);
    ci.imageFormat = format_;
    ci.imageColorSpace = color_space_;
    ci.imageExtent = {uint32_t(width_), uint32_t(height_)};
    ci.imageArrayLayers = 1;
    ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ci.preTransform = caps.currentTransform;
    ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // every driver has it
    ci.clipped = VK_TRUE;
    VIEW_CHECK(vkCreateSwapchainKHR(device_, &ci, nullptr, &swapchain_));
    vkGetSwapchainImagesKHR(device_, swapchain_, &n, nullptr);
    images_.resize(n);
    vkGetSwapchainImagesKHR(device_, swapchain_, &n, images_.data());
    // One semaphore an image between its copy and its present: a present may still wait on the
    // one it was given when the next frame's copy signals.
    rendered_.resize(n, VK_NULL_HANDLE);
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    for (VkSemaphore& s : rendered_) VIEW_CHECK(vkCreateSemaphore(device_, &sci, nullptr, &s));
    return create_staging(size_t(width_) * size_t(height_) * 4);
  }

  Status create_staging(size_t bytes) {
    if (bytes <= staging_bytes_) return ok_status();
    if (staging_) vkDestroyBuffer(device_, staging_, nullptr);
    if (staging_memory_) vkFreeMemory(device_, staging_memory_, nullptr);
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = bytes;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    VIEW_CHECK(vkCreateBuffer(device_, &bci, nullptr, &staging_));
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device_, staging_, &req);
    VkPhysicalDeviceMemoryProperties mp{};
    vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = ~0u;
    for (uint32_t i = 0; i < mp.memoryTypeCount && type == ~0u; ++i)
      if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) type = i;
    if (type == ~0u) return fail(ErrorKind::Device, "live view: no host-visible coherent memory for the staging copy");
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = type;
    VIEW_CHECK(vkAllocateMemory(device_, &mai, nullptr, &staging_memory_));
    VIEW_CHECK(vkBindBufferMemory(device_, staging_, staging_memory_, 0));
    VIEW_CHECK(vkMapMemory(device_, staging_memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    staging_bytes_ = bytes;
    return ok_status();
  }

  void destroy_swapchain() {
    for (VkSemaphore s : rendered_)
      if (s) vkDestroySemaphore(device_, s, nullptr);
    rendered_.clear();
    if (swapchain_) vkDestroySwapchainKHR(device_, swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
    images_.clear();
  }

  Status recreate_swapchain() {
    vkDeviceWaitIdle(device_);
    destroy_swapchain();
    return create_swapchain();
  }

  // The staging buffer into `image`: to TRANSFER_DST, the copy, to PRESENT_SRC.
  Status record_copy(VkImage image) {
    VIEW_CHECK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VIEW_CHECK(vkBeginCommandBuffer(cmd_, &bi));
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                         1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {uint32_t(width_), uint32_t(height_), 1};
    vkCmdCopyBufferToImage(cmd_, staging_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = 0;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VIEW_CHECK(vkEndCommandBuffer(cmd_));
    return ok_status();
  }

  std::string title_;
  int width_ = 0, height_ = 0;
  GLFWwindow* window_ = nullptr;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VulkanDeviceRequirements needs_;
  AppVulkanDevice app_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkColorSpaceKHR color_space_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  std::vector<VkImage> images_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  std::vector<VkSemaphore> rendered_;  // per swapchain image
  VkFence fence_ = VK_NULL_HANDLE;
  VkBuffer staging_ = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory_ = VK_NULL_HANDLE;
  size_t staging_bytes_ = 0;
  void* mapped_ = nullptr;
  ViewRequests requests_;
  bool side_by_side_ = false, show_stats_ = true, paused_ = false;
};

}  // namespace

Expected<std::unique_ptr<LiveView>> LiveView::open(const std::string& title, int width, int height,
                                                   const std::string& device_selector) {
  auto view = std::make_unique<GlfwView>();
  MRGI_TRY(view->init(title, width, height, device_selector));
  return std::unique_ptr<LiveView>(std::move(view));
}

}  // namespace mrgi::tool
