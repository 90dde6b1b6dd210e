// The live view of `mrgi replay --view` and `mrgi live --view`: a window showing each composite as
// it comes back. The view is the app: it creates its own Vulkan instance and device with a
// swapchain for the window (GLFW) and what mrgi needs (mrgi/vulkan_device.h), and the runtime runs
// on that device. Each composite goes from host memory into the swapchain image through one
// staging copy (the runtime's frames come back on the host today) and is presented.
//
// Keys: T next technique, [ and ] one level cheaper / better, S the camera frame beside the
// composite, I the frame's figures in the window title, Space pause, Q or Esc quit.
// Built with GLFW (Debian libglfw3-dev); without it LiveView::open says so (absent/).
#pragma once
#include <memory>
#include <string>

#include "mrgi/expected.h"
#include "mrgi/image.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"

namespace mrgi::tool {

// What the keys asked for since the last poll().
struct ViewRequests {
  bool next_technique = false;
  int level_step = 0;  // -1 better (]), +1 cheaper ([): level indices grow towards the cheapest
  bool quit = false;
};

class LiveView {
 public:
  // A window of width x height (the composite's size) titled `title`, on the Vulkan device
  // `device_selector` names (DeviceSettings::device's rules; empty: $MRGI_DEVICE, else lavapipe).
  // Device where there is no display ($DISPLAY unset, no X server) or no device can present.
  static Expected<std::unique_ptr<LiveView>> open(const std::string& title, int width, int height,
                                                  const std::string& device_selector);
  virtual ~LiveView() = default;
  // The device mrgi is to run on (DeviceSettings::app_device).
  virtual const AppVulkanDevice& device() const = 0;
  // Shows `composite`, and `camera` (the same size) to its left while side-by-side is on; `status`
  // (the frame's figures) goes into the title while I is on. Waits for the previous present.
  virtual Status show(const ImageRGBA8& composite, const ImageRGB8& camera, const std::string& status) = 0;
  // Handles the window's events; while paused (Space), waits in it until unpaused or quit.
  virtual ViewRequests poll() = 0;
  // Blocks until the window is closed or Q / Esc is pressed (the last frame stays up).
  virtual void hold() = 0;
  // The window's pixels as the X server holds them (XGetImage on the window), after every
  // present has completed: what the user sees.
  virtual Expected<ImageRGB8> screenshot() = 0;
};

// What replay and live do with the view's requests (view_control.cpp; built with or without GLFW):
// the title's figures for a frame; the level `step` away from the frame's, clamped to the ladder,
// set from the next frame on; the settings of the next technique of the registry (same level
// index where its ladder has one, else its cheapest; the knobs dropped: they were the first's).
std::string view_status(const Runtime& runtime, const FrameStats& stats);
Status step_level(Runtime& runtime, const FrameStats& stats, int step);
Expected<RuntimeSettings> next_technique_settings(const RuntimeSettings& current, const std::string& technique);

}  // namespace mrgi::tool
