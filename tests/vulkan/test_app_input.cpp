// Frames given as the app's own images (Runtime::process with AppInputImages,
// mrgi/vulkan_device.h): the test plays an app on its own device that fills one colour and one
// depth image per frame in its own submission (signalling the semaphore the runtime waits for)
// and gives them to the runtime, its composite into the app's image or read back. The frames
// must equal, value for value, the host path's with the same rule for the host's readers of the
// camera (RuntimeSettings::lagged_camera_reads: the frame frames_in_flight earlier), with no host
// copy of a frame image (FrameStats::host_copy_bytes 0 with the output on the device too) and no
// validation message; in every colour and depth format the runtime takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>

#include "app_images.h"
#include "app_vulkan.h"
#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";
constexpr int kFrames = 5;  // more than frames_in_flight + 1: lagged reads of real frames are compared

struct ImagesRun {
  std::string technique;
  std::string level;  // a level's name (technique_levels)
  VkFormat color_format;
  VkFormat depth_format;
  VkImageLayout layout;  // of both input images
  bool output_image;     // the composite into the app's image (else read back)
  // From frame kAway on, the camera turned away from the object: frames nothing virtual
  // affects (the camera frame as the output: read back from the uploads, or its camera words).
  bool look_away = false;
};
constexpr int kAway = 3;

int level_index(const std::string& technique, const std::string& name) {
  auto names = technique_levels(technique);
  if (!names) return -1;
  auto it = std::find(names->begin(), names->end(), name);
  return it == names->end() ? -1 : int(it - names->begin());
}

// The camera frame's bytes as the app's colour image holds them (4 a pixel, alpha 255).
std::vector<uint8_t> texels(const ImageRGB8& rgb, VkFormat format) {
  const bool bgra = format == VK_FORMAT_B8G8R8A8_UNORM || format == VK_FORMAT_B8G8R8A8_SRGB;
  std::vector<uint8_t> out(size_t(rgb.width) * size_t(rgb.height) * 4);
  for (size_t i = 0; i < out.size() / 4; ++i) {
    const uint8_t* p = &rgb.data[3 * i];
    out[4 * i + 0] = bgra ? p[2] : p[0];
    out[4 * i + 1] = p[1];
    out[4 * i + 2] = bgra ? p[0] : p[2];
    out[4 * i + 3] = 255;
  }
  return out;
}

struct Played {
  std::vector<FrameOutput> host;          // the host path, lagged camera reads
  std::vector<FrameOutput> app;           // the app-images path (images empty when output_image)
  std::vector<std::vector<uint8_t>> out;  // the app's output images read back, RGBA8
};

void play(AppVulkan& app, const ImagesRun& run, Played& played) {
  auto capture = CaptureReader::open(kSample);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  RuntimeSettings s;
  s.device.app_device = &app.app;
  s.technique = run.technique;
  s.level = level_index(run.technique, run.level);
  ASSERT_GE(s.level, 0) << run.technique << " has no level " << run.level;
  s.exposure = info.exposure;
  s.lagged_camera_reads = true;
  const CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  const uint32_t cw = uint32_t(info.color.width), ch = uint32_t(info.color.height);
  const uint32_t dw = uint32_t(info.depth.width), dh = uint32_t(info.depth.height);
  const VkImageAspectFlags depth_aspect =
      run.depth_format == VK_FORMAT_D16_UNORM ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  std::vector<AppImage> colors(kFrames), depths(kFrames), outputs(kFrames);
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(make_image(app, cw, ch, run.color_format, colors[size_t(i)]));
    ASSERT_TRUE(make_image(app, dw, dh, run.depth_format, depths[size_t(i)]));
    ASSERT_TRUE(make_image(app, cw, ch, VK_FORMAT_R8G8B8A8_UNORM, outputs[size_t(i)]));
  }
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
      if (run.look_away && i >= kAway && f->pose)
        f->pose->rotation = f->pose->rotation * glm::angleAxis(glm::pi<double>(), glm::dvec3(0.0, 1.0, 0.0));
      if (pass == 0) {
        take((*rt)->process(*f));
        continue;
      }
      const size_t k = size_t(i);
      const std::vector<uint8_t> c = texels(f->color, run.color_format);
      ASSERT_TRUE(fill(app, colors[k], cw, ch, c.data(), c.size(), VK_IMAGE_ASPECT_COLOR_BIT, run.layout, true));
      ASSERT_TRUE(fill(app, depths[k], dw, dh, f->depth.data.data(), f->depth.data.size() * 2, depth_aspect,
                       run.layout, false));
      f->color = ImageRGB8();
      f->depth = ImageU16();
      AppInputImages in;
      in.color = colors[k].image;
      in.color_format = run.color_format;
      in.color_layout = run.layout;
      in.depth = depths[k].image;
      in.depth_format = run.depth_format;
      in.depth_layout = run.layout;
      in.wait = colors[k].written;
      AppOutputImage target;
      target.image = outputs[k].image;
      target.old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
      target.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      target.signal = outputs[k].written;
      take((*rt)->process(*f, in, run.output_image ? &target : nullptr));
    }
    take((*rt)->flush());
    ASSERT_EQ(outs.size(), size_t(kFrames));
    (pass == 0 ? played.host : played.app) = std::move(outs);
  }
  if (run.output_image)
    for (int i = 0; i < kFrames; ++i) {
      ASSERT_TRUE(read_back(app, outputs[size_t(i)], cw, ch));
      const auto* p = static_cast<const uint8_t*>(outputs[size_t(i)].mapped);
      played.out.emplace_back(p, p + size_t(cw) * ch * 4);
    }
  for (int i = 0; i < kFrames; ++i)
    for (AppImage* img : {&colors[size_t(i)], &depths[size_t(i)], &outputs[size_t(i)]}) destroy_image(app, *img);
}

TEST(AppInput, TheAppsImagesGiveTheHostPathsFramesWithNoHostCopy) {
  AppVulkan app(true);
  ASSERT_TRUE(app.ok()) << "the test's app could not create its instance and device (validation layer installed?)";
  const VkImageLayout read_only = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  const ImagesRun runs[] = {
      // Into the app's image at the camera's size: the app's colour unpacked into the output's
      // camera words by the pass that unpacks it, compose's tiles over them.
      {"baseline", "medium", VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16_UINT, read_only, true},
      {"baseline", "lowest", VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_D16_UNORM, VK_IMAGE_LAYOUT_GENERAL, true},
      // A GI technique whose reuse test reads the host's (lagged) depth, the composite read back.
      {"dlpv", "fast", VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R16_UNORM, read_only, false},
      // ssrt estimates its light from the frames: its first frame runs twice (the app's
      // semaphore waited for once); then frames with nothing virtual in view, either way out.
      // (Read back: into an app's image compose composites ssrt's tiles itself, within 1/255 of
      // ssrt's own composite, RuntimeSettings::fuse_compose.)
      {"ssrt", "fast", VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16_UINT, read_only, false, true},
      {"baseline", "lowest", VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16_UINT, read_only, true, true},
  };
  for (const ImagesRun& run : runs) {
    SCOPED_TRACE(run.technique + " " + run.level + (run.output_image ? ", into the app's image" : ", read back"));
    Played p;
    play(app, run, p);
    if (HasFatalFailure()) return;
    for (size_t i = 0; i < size_t(kFrames); ++i) {
      const FrameOutput& h = p.host[i];
      const FrameOutput& a = p.app[i];
      ASSERT_FALSE(h.image.data.empty());
      size_t differing = 0, mask_wrong = 0, masked = 0;
      for (size_t k = 0; k < h.virtual_mask.data.size(); ++k) {
        const uint8_t* got = run.output_image ? &p.out[i][4 * k] : &a.image.data[4 * k];
        const uint8_t mask = run.output_image ? got[3] : a.virtual_mask.data[k];
        for (int c = 0; c < 3; ++c) differing += got[c] != h.image.data[4 * k + c];
        mask_wrong += mask != h.virtual_mask.data[k];
        masked += h.virtual_mask.data[k] != 0;
      }
      EXPECT_EQ(differing, 0u) << "frame " << i << ": values differing from the host path's";
      EXPECT_EQ(mask_wrong, 0u) << "frame " << i << ": the virtual mask";
      if (run.look_away && i >= size_t(kAway))
        EXPECT_EQ(masked, 0u) << "frame " << i << ": the camera looks away from the object";
      else
        EXPECT_GT(masked, 0u) << "frame " << i << ": the object is in view";
      // No frame image is copied by the host: nothing at all with the output on the device, the
      // read-back composite and mask otherwise.
      const uint64_t readback = run.output_image ? 0 : a.image.data.size() + a.virtual_mask.data.size();
      EXPECT_EQ(a.stats.host_copy_bytes, readback) << "frame " << i;
      EXPECT_GT(h.stats.host_copy_bytes, readback) << "frame " << i << ": the host path uploads";
    }
  }
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

TEST(AppInput, ImagesAreRefusedByNameWhereTheyCannotBeRead) {
  auto capture = CaptureReader::open(kSample);
  ASSERT_TRUE(capture.ok()) << capture.error().message;
  const CaptureInfo& info = capture->info();
  const CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  auto frame = capture->read_frame(0);
  ASSERT_TRUE(frame.ok());
  InputFrame meta = *frame;  // the frame without its images, as an app giving images sends it
  meta.color = ImageRGB8();
  meta.depth = ImageU16();
  AppInputImages in;
  in.color = reinterpret_cast<VkImage>(uintptr_t(0x1234));  // never used: refused before
  in.depth = reinterpret_cast<VkImage>(uintptr_t(0x5678));
  auto expect_refused = [](Runtime& rt, const InputFrame& f, const AppInputImages& images, const std::string& says) {
    auto r = rt.process(f, images);
    ASSERT_FALSE(r.ok()) << "accepted; expected a refusal naming " << says;
    EXPECT_EQ(r.error().kind, ErrorKind::BadUsage);
    EXPECT_NE(r.error().message.find(says), std::string::npos) << r.error().message;
  };
  {
    RuntimeSettings own;
    own.level = 1;
    auto rt = create_runtime(own, cameras, *capture->scene());
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    expect_refused(**rt, meta, in, "DeviceSettings::app_device");
  }
  AppVulkan app(true);
  ASSERT_TRUE(app.ok());
  RuntimeSettings s;
  s.device.app_device = &app.app;
  s.level = 1;
  auto rt = create_runtime(s, cameras, *capture->scene());
  ASSERT_TRUE(rt.ok()) << rt.error().message;
  expect_refused(**rt, *frame, in, "InputFrame::color, color_yuv and depth must be empty");
  AppInputImages bad = in;
  bad.color = VK_NULL_HANDLE;
  expect_refused(**rt, meta, bad, "AppInputImages::color is null");
  bad = in;
  bad.depth = VK_NULL_HANDLE;
  expect_refused(**rt, meta, bad, "AppInputImages::depth is null");
  bad = in;
  bad.color_format = VK_FORMAT_R8G8B8_UNORM;
  expect_refused(**rt, meta, bad, "AppInputImages::color_format");
  bad = in;
  bad.depth_format = VK_FORMAT_R32_SFLOAT;
  expect_refused(**rt, meta, bad, "AppInputImages::depth_format");
  bad = in;
  bad.depth_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  expect_refused(**rt, meta, bad, "AppInputImages::depth_layout");
  AppOutputImage target;
  target.image = VK_NULL_HANDLE;
  auto r = (*rt)->process(meta, in, &target);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("AppOutputImage::image is null"), std::string::npos) << r.error().message;
  // One binary semaphore as both waits (never used: refused before).
  AppInputImages waits = in;
  waits.wait = reinterpret_cast<VkSemaphore>(uintptr_t(0x9abc));
  target.image = reinterpret_cast<VkImage>(uintptr_t(0xdef0));
  target.wait = waits.wait;
  r = (*rt)->process(meta, waits, &target);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("AppInputImages::wait and AppOutputImage::wait are the same semaphore"),
            std::string::npos) << r.error().message;
  for (const std::string& m : app.messages()) ADD_FAILURE() << "validation: " << m;
}

}  // namespace
}  // namespace mrgi::test
