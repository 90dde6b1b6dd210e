// The composite written into the app's own image (Runtime::process with an AppOutputImage,
// mrgi/vulkan_device.h): the test plays an app on its own device that gives the runtime one
// image per frame and a semaphore the runtime signals, waits for it in its own submission that
// reads the image back, and checks that the images hold the frames the host path returns (at the
// camera's size, where compose lays its tiles over the camera frame on the host, and at a
// reduced internal scale), their alpha the virtual mask, with no validation message, and that
// no host copy of the output was made (FrameStats::host_copy_bytes).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "app_vulkan.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";
constexpr int kFrames = 4;

// One image of the app's with a host-visible buffer to read it back into.
struct AppImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkBuffer readback = VK_NULL_HANDLE;
  VkDeviceMemory readback_memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkSemaphore written = VK_NULL_HANDLE;  // signalled by the runtime
};

uint32_t memory_type(VkPhysicalDevice pd, uint32_t bits, VkMemoryPropertyFlags want) {
  VkPhysicalDeviceMemoryProperties mp{};
  vkGetPhysicalDeviceMemoryProperties(pd, &mp);
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
  return ~0u;
}

bool make_image(AppVulkan& app, uint32_t w, uint32_t h, AppImage& out) {
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = VK_FORMAT_R8G8B8A8_UNORM;
  ici.extent = {w, h, 1};
  ici.mipLevels = ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (vkCreateImage(app.device, &ici, nullptr, &out.image) != VK_SUCCESS) return false;
  VkMemoryRequirements mr{};
  vkGetImageMemoryRequirements(app.device, out.image, &mr);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = mr.size;
  mai.memoryTypeIndex = memory_type(app.physical, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (vkAllocateMemory(app.device, &mai, nullptr, &out.memory) != VK_SUCCESS) return false;
  vkBindImageMemory(app.device, out.image, out.memory, 0);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = VkDeviceSize(w) * h * 4;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (vkCreateBuffer(app.device, &bci, nullptr, &out.readback) != VK_SUCCESS) return false;
  vkGetBufferMemoryRequirements(app.device, out.readback, &mr);
  mai.allocationSize = mr.size;
  mai.memoryTypeIndex = memory_type(app.physical, mr.memoryTypeBits,
                                    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (vkAllocateMemory(app.device, &mai, nullptr, &out.readback_memory) != VK_SUCCESS) return false;
  vkBindBufferMemory(app.device, out.readback, out.readback_memory, 0);
  vkMapMemory(app.device, out.readback_memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  return vkCreateSemaphore(app.device, &sci, nullptr, &out.written) == VK_SUCCESS;
}

void destroy_image(AppVulkan& app, AppImage& i) {
  vkDestroySemaphore(app.device, i.written, nullptr);
  vkDestroyBuffer(app.device, i.readback, nullptr);
  vkFreeMemory(app.device, i.readback_memory, nullptr);
  vkDestroyImage(app.device, i.image, nullptr);
  vkFreeMemory(app.device, i.memory, nullptr);
}

// The app's own submission: waits for the runtime's semaphore, copies the image (left by the
// runtime in TRANSFER_SRC_OPTIMAL) into its readback buffer; waited for on a fence.
bool read_back(AppVulkan& app, const AppImage& img, uint32_t w, uint32_t h) {
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = app.family;
  VkCommandPool pool = VK_NULL_HANDLE;
  vkCreateCommandPool(app.device, &pci, nullptr, &pool);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vkAllocateCommandBuffers(app.device, &cai, &cmd);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &bi);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {w, h, 1};
  vkCmdCopyImageToBuffer(cmd, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img.readback, 1, &region);
  vkEndCommandBuffer(cmd);
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &img.written;
  si.pWaitDstStageMask = &stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  vkCreateFence(app.device, &fci, nullptr, &fence);
  bool ok = vkQueueSubmit(app.queue, 1, &si, fence) == VK_SUCCESS &&
            vkWaitForFences(app.device, 1, &fence, VK_TRUE, 30'000'000'000ull) == VK_SUCCESS;
  vkDestroyFence(app.device, fence, nullptr);
  vkDestroyCommandPool(app.device, pool, nullptr);
  return ok;
}

struct Played {
  std::vector<FrameOutput> host;           // through process(frame)
  std::vector<std::vector<uint8_t>> app;   // the app's images read back, RGBA8
  std::vector<FrameStats> app_stats;
};

// The sample's first kFrames frames at `level` (output `half` the camera's size or its own),
// once through the host path and once into the app's images, on the same app device.
void play(AppVulkan& app, int level, bool half, Played& out) {
  auto capture = CaptureReader::open(kSample);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  RuntimeSettings s;
  s.device.app_device = &app.app;
  s.technique = "baseline";
  s.level = level;
  s.exposure = info.exposure;
  const uint32_t w = uint32_t(info.color.width) / (half ? 2 : 1), h = uint32_t(info.color.height) / (half ? 2 : 1);
  s.output_width = int(w);
  s.output_height = int(h);
  const CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  std::vector<AppImage> images(kFrames);
  for (AppImage& i : images) ASSERT_TRUE(make_image(app, w, h, i));
  for (int pass = 0; pass < 2; ++pass) {
    auto rt = create_runtime(s, cameras, *capture->scene());
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    std::vector<FrameOutput> outs;
    auto take = [&](Expected<std::vector<FrameOutput>>&& o) {
      ASSERT_TRUE(o.ok()) << o.error().message;
      for (FrameOutput& f : *o) outs.push_back(std::move(f));
    };
    for (int i = 0; i < kFrames; ++i) {
      auto f = capture->read_frame(size_t(i));
      ASSERT_TRUE(f.ok()) << f.error().message;
      f->index = i;
      if (pass == 0) {
        take((*rt)->process(*f));
      } else {
        AppOutputImage target;
        target.image = images[size_t(i)].image;
        target.format = VK_FORMAT_R8G8B8A8_UNORM;
        target.old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
        target.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        target.signal = images[size_t(i)].written;
        take((*rt)->process(*f, target));
      }
    }
    take((*rt)->flush());
    ASSERT_EQ(outs.size(), size_t(kFrames));
    if (pass == 0) {
      out.host = std::move(outs);
      continue;
    }
    for (int i = 0; i < kFrames; ++i) {
      EXPECT_TRUE(outs[size_t(i)].image.data.empty()) << "frame " << i << ": its image went to the app";
      out.app_stats.push_back(outs[size_t(i)].stats);
      ASSERT_TRUE(read_back(app, images[size_t(i)], w, h));
      const auto* p = static_cast<const uint8_t*>(images[size_t(i)].mapped);
      out.app.emplace_back(p, p + size_t(w) * h * 4);
    }
  }
  for (AppImage& i : images) destroy_image(app, i);
}

TEST(AppOutput, TheAppsImagesHoldTheHostPathsFramesWithNoHostCopyOfTheOutput) {
  AppVulkan app(true);
  ASSERT_TRUE(app.ok()) << "the test's app could not create its instance and device (validation layer installed?)";
  // Level 1: solutions at the camera's size, compose's tiles laid over the camera frame on the
  // host path (into the app's image: the host expands the camera under them on lavapipe); the
  // lowest level: a reduced internal scale; an output of half the camera's size: the camera
  // resampled by compose's camera pass on the device either way.
  const int lowest = int(technique_levels("baseline")->size()) - 1;
  const struct {
    int level;
    bool half;
  } runs[] = {{1, false}, {lowest, false}, {1, true}};
  for (const auto& run : runs) {
    SCOPED_TRACE("level " + std::to_string(run.level) + (run.half ? ", half-size output" : ""));
    const bool half = run.half;
    Played p;
    play(app, run.level, half, p);
    if (HasFatalFailure()) return;
    ASSERT_EQ(p.app.size(), size_t(kFrames));
    for (size_t i = 0; i < p.app.size(); ++i) {
      const FrameOutput& h = p.host[i];
      size_t differing = 0, mask_wrong = 0, masked = 0;
      for (size_t k = 0; k < h.virtual_mask.data.size(); ++k) {
        for (int c = 0; c < 3; ++c) differing += p.app[i][4 * k + c] != h.image.data[4 * k + c];
        mask_wrong += p.app[i][4 * k + 3] != h.virtual_mask.data[k];
        masked += h.virtual_mask.data[k] != 0;
      }
      EXPECT_EQ(differing, 0u) << "frame " << i << ": values differing from the host path's";
      EXPECT_EQ(mask_wrong, 0u) << "frame " << i << ": alpha is the virtual mask";
      EXPECT_GT(masked, 0u) << "frame " << i << ": the object is in view";
      const uint64_t pixels = uint64_t(h.image.width) * h.image.height;
      // Nothing of the output is copied; on a CPU device (lavapipe) the host expands the camera
      // frame under the composite's tiles (4 bytes a pixel) instead of a pass doing it.
      const uint64_t camera = uint64_t(h.image.width) * h.image.height * (half ? 4 : 1);  // the camera's pixels
      const uint64_t input = camera * 5;  // RGB8 + u16 depth
      EXPECT_EQ(p.app_stats[i].host_copy_bytes, input + (half ? 0 : pixels * 4)) << "frame " << i << ": the output is not copied";
      EXPECT_EQ(h.stats.host_copy_bytes, input + h.image.data.size() + h.virtual_mask.data.size()) << "frame " << i;
    }
  }
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

TEST(AppOutput, ATargetIsRefusedByNameWhereItCannotBeWritten) {
  auto capture = CaptureReader::open(kSample);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  const CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  auto frame = capture->read_frame(0);
  ASSERT_TRUE(frame.ok());
  AppOutputImage target;
  target.image = reinterpret_cast<VkImage>(uintptr_t(0x1234));  // never used: refused before
  {
    RuntimeSettings own;
    own.level = 1;
    auto rt = create_runtime(own, cameras, *capture->scene());
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    auto r = (*rt)->process(*frame, target);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, ErrorKind::BadUsage);
    EXPECT_NE(r.error().message.find("DeviceSettings::app_device"), std::string::npos) << r.error().message;
  }
  AppVulkan app(true);
  ASSERT_TRUE(app.ok());
  RuntimeSettings s;
  s.device.app_device = &app.app;
  s.level = 1;
  auto rt = create_runtime(s, cameras, *capture->scene());
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  AppOutputImage bad = target;
  bad.format = VK_FORMAT_B8G8R8A8_UNORM;
  auto r = (*rt)->process(*frame, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("AppOutputImage::format"), std::string::npos) << r.error().message;
  bad = target;
  bad.final_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  r = (*rt)->process(*frame, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("final_layout"), std::string::npos) << r.error().message;
  bad = target;
  bad.image = VK_NULL_HANDLE;
  r = (*rt)->process(*frame, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("image is null"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace mrgi::test
