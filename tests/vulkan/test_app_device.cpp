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
#include "app_vulkan.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";

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
