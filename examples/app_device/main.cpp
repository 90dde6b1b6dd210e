// An app that already renders with Vulkan runs mrgi on its own instance, device and queue
// (mrgi/vulkan_device.h): it asks mrgi what to enable, creates its device with that (and what it
// needs itself), hands the objects to create_runtime, plays a recorded capture through the
// runtime, and goes on using its device after the runtime is gone.
//
//   app_device CAPTURE_DIR [FRAMES] [--input host|image] [--output host|image] [--technique NAME]
//              [--level N] [--profile]
//
// --input image: the capture's frames are the app's images (an RGBA8 colour and an R16 depth
// image each, filled once at start, as a camera's frames would already be on the device), given
// to the runtime as mrgi::AppInputImages; the host copies none of them. --input host (the
// default): host-memory frames the runtime uploads.
// --output image: the composites go straight into the app's images (mrgi::AppOutputImage), with
// the semaphore the app's "present" waits for; no readback. --output host (the default): they
// come back in host memory and the app copies each into its image (as an app that presents them
// must); the bytes the host copied a frame count both (with --input image and --output image:
// none). --profile: each pass submitted on its own (RuntimeSettings::profile_passes) and the
// median CPU ms of each over the frames after the warm-up printed. Prints the device, what was enabled
// for mrgi, each frame's output (up to 8 frames) and the sustained wall and CPU ms a frame after
// a 4-frame warm-up. Exit 0 when every frame came back and the device still works afterwards.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
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

// The app's images the composites go into: a ring, each with the semaphore the runtime signals
// when it wrote one (--output image) and the app's "present" (a submission that waits for that
// semaphore, as a swapchain's present would), or, on the host path, the app's own copy of the
// returned composite into it; fenced so an image is reused only after it.
class ImageRing {
 public:
  bool create(VkPhysicalDevice physical, VkDevice device, VkQueue queue, uint32_t family, uint32_t w, uint32_t h) {
    device_ = device;
    queue_ = queue;
    VkPhysicalDeviceMemoryProperties mp{};
    vkGetPhysicalDeviceMemoryProperties(physical, &mp);
    for (Slot& s : slots_) {
      VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
      ici.imageType = VK_IMAGE_TYPE_2D;
      ici.format = VK_FORMAT_R8G8B8A8_UNORM;
      ici.extent = {w, h, 1};
      ici.mipLevels = ici.arrayLayers = 1;
      ici.samples = VK_SAMPLE_COUNT_1_BIT;
      ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
      if (vkCreateImage(device, &ici, nullptr, &s.image) != VK_SUCCESS) return false;
      VkMemoryRequirements mr{};
      vkGetImageMemoryRequirements(device, s.image, &mr);
      VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
      mai.allocationSize = mr.size;
      for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        if (mr.memoryTypeBits & (1u << i)) {
          mai.memoryTypeIndex = i;
          break;
        }
      if (vkAllocateMemory(device, &mai, nullptr, &s.memory) != VK_SUCCESS) return false;
      vkBindImageMemory(device, s.image, s.memory, 0);
      VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
      fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
      if (vkCreateSemaphore(device, &sci, nullptr, &s.written) != VK_SUCCESS ||
          vkCreateFence(device, &fci, nullptr, &s.presented) != VK_SUCCESS)
        return false;
      // For the host path: a host-visible buffer the returned image is copied into, and a
      // command buffer that copies it into the image.
      VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
      bci.size = VkDeviceSize(w) * h * 4;
      bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
      if (vkCreateBuffer(device, &bci, nullptr, &s.staging) != VK_SUCCESS) return false;
      vkGetBufferMemoryRequirements(device, s.staging, &mr);
      mai.allocationSize = mr.size;
      const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        if ((mr.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & host) == host) {
          mai.memoryTypeIndex = i;
          break;
        }
      if (vkAllocateMemory(device, &mai, nullptr, &s.staging_memory) != VK_SUCCESS) return false;
      vkBindBufferMemory(device, s.staging, s.staging_memory, 0);
      vkMapMemory(device, s.staging_memory, 0, VK_WHOLE_SIZE, 0, &s.mapped);
    }
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = family;
    if (vkCreateCommandPool(device, &pci, nullptr, &pool_) != VK_SUCCESS) return false;
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool_;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    for (Slot& s : slots_)
      if (vkAllocateCommandBuffers(device, &cai, &s.cmd) != VK_SUCCESS) return false;
    w_ = w;
    h_ = h;
    return true;
  }
  // The host path's way into the app's image: the returned composite copied into the next
  // image's staging buffer on the host, then into the image by the app's own submission.
  void upload(const mrgi::ImageRGBA8& composite) {
    Slot& s = slots_[next_];
    vkWaitForFences(device_, 1, &s.presented, VK_TRUE, UINT64_MAX);
    vkResetFences(device_, 1, &s.presented);
    std::memcpy(s.mapped, composite.data.data(), std::min<size_t>(composite.data.size(), size_t(w_) * h_ * 4));
    vkResetCommandBuffer(s.cmd, 0);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(s.cmd, &bi);
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = 0;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = s.image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(s.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {w_, h_, 1};
    vkCmdCopyBufferToImage(s.cmd, s.staging, s.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    vkCmdPipelineBarrier(s.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    vkEndCommandBuffer(s.cmd);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &s.cmd;
    vkQueueSubmit(queue_, 1, &si, s.presented);
    next_ = (next_ + 1) % kSlots;
  }
  // The next image, once the app's last use of it is done.
  mrgi::AppOutputImage next() {
    Slot& s = slots_[next_];
    vkWaitForFences(device_, 1, &s.presented, VK_TRUE, UINT64_MAX);
    vkResetFences(device_, 1, &s.presented);
    mrgi::AppOutputImage t;
    t.image = s.image;
    t.format = VK_FORMAT_R8G8B8A8_UNORM;
    t.old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    t.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    t.signal = s.written;
    return t;
  }
  // The app takes the image the last next() gave (after process() submitted the frame).
  void present() {
    Slot& s = slots_[next_];
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &s.written;
    si.pWaitDstStageMask = &stage;
    vkQueueSubmit(queue_, 1, &si, s.presented);
    next_ = (next_ + 1) % kSlots;
  }
  void destroy() {
    if (!device_) return;  // never created
    for (Slot& s : slots_) {
      if (s.presented) vkWaitForFences(device_, 1, &s.presented, VK_TRUE, UINT64_MAX);
      vkDestroyFence(device_, s.presented, nullptr);
      vkDestroyBuffer(device_, s.staging, nullptr);
      vkFreeMemory(device_, s.staging_memory, nullptr);
      vkDestroySemaphore(device_, s.written, nullptr);
      vkDestroyImage(device_, s.image, nullptr);
      vkFreeMemory(device_, s.memory, nullptr);
    }
    vkDestroyCommandPool(device_, pool_, nullptr);
  }

 private:
  static constexpr int kSlots = 3;
  struct Slot {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkSemaphore written = VK_NULL_HANDLE;
    VkFence presented = VK_NULL_HANDLE;
    VkBuffer staging = VK_NULL_HANDLE;
    VkDeviceMemory staging_memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
  } slots_[kSlots];
  VkCommandPool pool_ = VK_NULL_HANDLE;
  uint32_t w_ = 0, h_ = 0;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  int next_ = 0;
};

// The capture's frames as the app's images (--input image): colour RGBA8 and depth R16_UINT,
// filled once through a host-visible buffer by the app's own submission.
class InputImages {
 public:
  bool create(VkPhysicalDevice physical, VkDevice device, VkQueue queue, uint32_t family,
              const std::vector<mrgi::InputFrame>& frames) {
    device_ = device;
    vkGetPhysicalDeviceMemoryProperties(physical, &mp_);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = family;
    if (vkCreateCommandPool(device, &pci, nullptr, &pool_) != VK_SUCCESS) return false;
    for (const mrgi::InputFrame& f : frames) {
      std::vector<uint8_t> rgba(f.color.data.size() / 3 * 4, 255);
      for (size_t i = 0; i < rgba.size() / 4; ++i) std::memcpy(&rgba[4 * i], &f.color.data[3 * i], 3);
      mrgi::AppInputImages in;
      in.color_format = VK_FORMAT_R8G8B8A8_UNORM;
      in.depth_format = VK_FORMAT_R16_UINT;
      if (!image(in.color_format, f.color.width, f.color.height, rgba.data(), rgba.size(), queue, in.color) ||
          !image(in.depth_format, f.depth.width, f.depth.height, f.depth.data.data(), f.depth.data.size() * 2, queue,
                 in.depth))
        return false;
      frames_.push_back(in);
    }
    return true;
  }
  const mrgi::AppInputImages& frame(size_t i) const { return frames_[i]; }
  void destroy() {
    for (size_t i = 0; i < images_.size(); ++i) {
      vkDestroyImage(device_, images_[i], nullptr);
      vkFreeMemory(device_, memory_[i], nullptr);
    }
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
  }

 private:
  uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags want) const {
    for (uint32_t i = 0; i < mp_.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (mp_.memoryTypes[i].propertyFlags & want) == want) return i;
    return 0;
  }
  // One image in SHADER_READ_ONLY_OPTIMAL holding `bytes`.
  bool image(VkFormat format, int w, int h, const void* bytes, size_t size, VkQueue queue, VkImage& out) {
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {uint32_t(w), uint32_t(h), 1};
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    if (vkCreateImage(device_, &ici, nullptr, &out) != VK_SUCCESS) return false;
    VkMemoryRequirements mr{};
    vkGetImageMemoryRequirements(device_, out, &mr);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = mr.size;
    mai.memoryTypeIndex = memory_type(mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (vkAllocateMemory(device_, &mai, nullptr, &memory) != VK_SUCCESS) return false;
    vkBindImageMemory(device_, out, memory, 0);
    images_.push_back(out);
    memory_.push_back(memory);
    // The fill: a staging buffer, a copy, the image left for reading.
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    VkBuffer staging = VK_NULL_HANDLE;
    if (vkCreateBuffer(device_, &bci, nullptr, &staging) != VK_SUCCESS) return false;
    vkGetBufferMemoryRequirements(device_, staging, &mr);
    mai.allocationSize = mr.size;
    mai.memoryTypeIndex =
        memory_type(mr.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory staging_memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    if (vkAllocateMemory(device_, &mai, nullptr, &staging_memory) != VK_SUCCESS) return false;
    vkBindBufferMemory(device_, staging, staging_memory, 0);
    vkMapMemory(device_, staging_memory, 0, VK_WHOLE_SIZE, 0, &mapped);
    std::memcpy(mapped, bytes, size);
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool_;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    vkAllocateCommandBuffers(device_, &cai, &cmd);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmd, &bi);
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = out;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = ici.extent;
    vkCmdCopyBufferToImage(cmd, staging, out, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    vkEndCommandBuffer(cmd);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    const bool ok = vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS && vkQueueWaitIdle(queue) == VK_SUCCESS;
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    vkDestroyBuffer(device_, staging, nullptr);
    vkFreeMemory(device_, staging_memory, nullptr);
    return ok;
  }
  VkDevice device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties mp_{};
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<VkImage> images_;
  std::vector<VkDeviceMemory> memory_;
  std::vector<mrgi::AppInputImages> frames_;
};

struct Options {
  int frames = 4;         // frames played (the capture's, looped forwards and back)
  bool from_images = false;  // --input image: frames as the app's images
  bool to_image = false;  // --output image: composites into the app's images
  bool profile = false;   // --profile: the per-pass split
  std::string level;      // --level N (default: the scheduler's)
  std::string technique;  // --technique NAME (default: baseline)
};

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

using PassSamples = std::vector<std::pair<std::string, std::vector<double>>>;  // per pass, per frame

// --profile: each pass's median CPU ms over the frames it ran in.
void print_pass_medians(PassSamples& passes) {
  for (auto& [name, ms] : passes) {
    std::sort(ms.begin(), ms.end());
    std::printf("  pass %-28s %6.2f CPU ms (median of %zu frames)\n", name.c_str(), ms[ms.size() / 2], ms.size());
  }
}

// Plays the capture's frames (preloaded) through a runtime on the app's device, into host memory
// or the app's images; after 4 warm-up frames, prints the sustained wall and CPU ms a frame.
int play(const mrgi::AppVulkanDevice& app, const std::string& capture_dir, const Options& o) {
  auto capture = mrgi::CaptureReader::open(capture_dir);
  if (!capture) return fail(capture.error().message);
  const mrgi::CaptureInfo& info = capture->info();
  std::vector<mrgi::InputFrame> frames;
  for (size_t i = 0; i < capture->frame_count(); ++i) {
    auto f = capture->read_frame(i);
    if (!f) return fail(f.error().message);
    frames.push_back(std::move(*f));
  }
  if (frames.empty()) return fail(capture_dir + ": no frames");
  mrgi::RuntimeSettings settings;
  settings.device.app_device = &app;
  settings.exposure = info.exposure;
  if (!o.level.empty()) settings.level = std::atoi(o.level.c_str());
  if (!o.technique.empty()) settings.technique = o.technique;
  settings.profile_passes = o.profile;
  auto runtime = mrgi::create_runtime(
      settings, mrgi::CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera},
      *capture->scene());
  if (!runtime) return fail(runtime.error().message);
  std::printf("runtime on the app's device: %s, frames from %s, composites into %s\n", (*runtime)->device().name.c_str(),
              o.from_images ? "the app's images" : "host memory", o.to_image ? "the app's images" : "host memory");
  InputImages inputs;
  if (o.from_images) {
    if (!inputs.create(app.physical_device, app.device, app.queue, app.queue_family, frames))
      return fail("the app could not create its input images");
    for (mrgi::InputFrame& f : frames) {  // what stays in host memory: index, times, pose, env
      f.color = mrgi::ImageRGB8();
      f.depth = mrgi::ImageU16();
    }
  }
  // The app's images: the composites go into them either way (straight, or copied there from
  // host memory by the app, as an app that presents them must).
  ImageRing ring;
  if (!ring.create(app.physical_device, app.device, app.queue, app.queue_family, uint32_t(info.color.width),
                   uint32_t(info.color.height)))
    return fail("the app could not create its images");
  int returned = 0;
  uint64_t copied = 0;
  PassSamples pass_cpu;  // --profile
  auto report = [&](std::vector<mrgi::FrameOutput>& outs) {
    for (mrgi::FrameOutput& out : outs) {
      if (o.profile && out.stats.frame_index >= 4)
        for (const mrgi::PassTiming& t : out.stats.passes) {
          auto it = std::find_if(pass_cpu.begin(), pass_cpu.end(), [&](const auto& p) { return p.first == t.name; });
          if (it == pass_cpu.end()) it = pass_cpu.insert(pass_cpu.end(), {t.name, {}});
          it->second.push_back(t.cpu_ms);
        }
      if (o.frames <= 8)
        std::printf("frame %lld: %s, cost %.1f ms, %llu bytes copied by the host\n",
                    static_cast<long long>(out.stats.frame_index),
                    out.image.empty() ? "in the app's image" : "in host memory", out.stats.cost_ms,
                    static_cast<unsigned long long>(out.stats.host_copy_bytes));
      copied += out.stats.host_copy_bytes;
      if (!out.image.empty()) {
        ring.upload(out.image);  // the host path: the app copies the composite into its image
        copied += out.image.data.size();
      }
      ++returned;
      (*runtime)->recycle(std::move(out));
    }
  };
  constexpr int kWarmUp = 4;
  double wall0 = 0.0, cpu0 = 0.0;
  const size_t n = frames.size(), period = n > 1 ? 2 * (n - 1) : 1;
  for (int i = 0; i < o.frames; ++i) {
    if (i == std::min(kWarmUp, o.frames - 1)) {
      wall0 = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
      cpu0 = process_cpu_ms();
    }
    const size_t k = size_t(i) % period;
    const size_t which = k < n ? k : period - k;
    mrgi::InputFrame& frame = frames[which];
    frame.index = i;
    frame.timestamp = frame.depth_timestamp = double(i) / 30.0;
    mrgi::AppOutputImage target;
    if (o.to_image) target = ring.next();
    auto outs = o.from_images ? (*runtime)->process(frame, inputs.frame(which), o.to_image ? &target : nullptr)
                : o.to_image  ? (*runtime)->process(frame, target)
                              : (*runtime)->process(frame);
    if (!outs) return fail(outs.error().message);
    if (o.to_image) ring.present();
    report(*outs);
  }
  auto rest = (*runtime)->flush();
  if (!rest) return fail(rest.error().message);
  report(*rest);
  const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count() - wall0;
  const double cpu = process_cpu_ms() - cpu0;
  const int timed = o.frames - std::min(kWarmUp, o.frames - 1);
  std::printf("%d frames after the warm-up: %.2f ms a frame sustained, %.2f CPU ms a frame; %.0f bytes a frame copied by the host\n",
              timed, wall / timed, cpu / timed, double(copied) / std::max(returned, 1));
  print_pass_medians(pass_cpu);
  runtime->reset();
  ring.destroy();
  inputs.destroy();
  return returned == o.frames ? 0 : fail(std::to_string(returned) + " of " + std::to_string(o.frames) + " frames came back");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s CAPTURE_DIR [FRAMES] [--input host|image] [--output host|image] [--technique NAME] [--level N] [--profile]\n", argv[0]);
    return 2;
  }
  Options options;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--input" && i + 1 < argc) {
      const std::string v = argv[++i];
      if (v != "host" && v != "image") return fail("--input: host or image, not '" + v + "'");
      options.from_images = v == "image";
    } else if (a == "--output" && i + 1 < argc) {
      const std::string v = argv[++i];
      if (v != "host" && v != "image") return fail("--output: host or image, not '" + v + "'");
      options.to_image = v == "image";
    } else if (a == "--profile") {
      options.profile = true;
    } else if (a == "--level" && i + 1 < argc) {
      options.level = argv[++i];
    } else if (a == "--technique" && i + 1 < argc) {
      options.technique = argv[++i];
    } else if (std::atoi(a.c_str()) > 0) {
      options.frames = std::atoi(a.c_str());
    } else {
      return fail("unknown argument '" + a + "' (--help)");
    }
  }

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
  int status = play(app, argv[1], options);

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
