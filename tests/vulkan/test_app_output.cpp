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

#include "app_images.h"
#include "app_vulkan.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";
constexpr int kFrames = 4;

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
  for (AppImage& i : images) ASSERT_TRUE(make_image(app, w, h, VK_FORMAT_R8G8B8A8_UNORM, i));
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
      const uint64_t input = camera * 6;  // colour words (4 bytes a pixel) + u16 depth
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
