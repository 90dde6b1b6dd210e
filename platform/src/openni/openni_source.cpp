// OpenNI2 adapter: live devices and .oni playback behind mrgi::InputSource.
#include "mrgi/platform/openni.h"

#include <OpenNI.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

#include "openni/oni_file_inspector.h"

namespace mrgi {
namespace {

using Clock = std::chrono::steady_clock;

std::string openni_error_text() {
  std::string s = openni::OpenNI::getExtendedError();
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  while (!s.empty() && (s.front() == '\t' || s.front() == ' ')) s.erase(s.begin());
  return s.empty() ? std::string("no error text from OpenNI2") : s;
}

bool ends_with_ignoring_case(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                                                 [](char a, char b) { return std::tolower(a) == b; });
}

// Pinhole intrinsics from the stream's fields of view: fx = (w/2) / tan(hfov/2).
Intrinsics intrinsics_from_fov(int w, int h, double hfov, double vfov) {
  Intrinsics k;
  k.width = w;
  k.height = h;
  k.fx = 0.5 * w / std::tan(0.5 * hfov);
  k.fy = 0.5 * h / std::tan(0.5 * vfov);
  k.cx = 0.5 * (w - 1);  // pixel centres at integers (OpenCV/TUM convention)
  k.cy = 0.5 * (h - 1);
  return k;
}

bool fov_valid(float hfov, float vfov) {
  return std::isfinite(hfov) && std::isfinite(vfov) && hfov > 0.05f && hfov < 3.1f && vfov > 0.05f && vfov < 3.1f;
}

// OpenNI2 hands a second Device::open of an already open URI the same underlying device (for a
// file: the same, possibly finished, playback), so one URI is open at most once per process.
std::mutex& open_uris_mutex() {
  static std::mutex m;
  return m;
}
std::set<std::string>& open_uris() {
  static std::set<std::string> s;
  return s;
}

class OpenNISource final : public InputSource {
 public:
  ~OpenNISource() override {
    depth_.stop();
    color_.stop();
    depth_.destroy();
    color_.destroy();
    device_.close();
    if (!claimed_.empty()) {
      std::lock_guard<std::mutex> lock(open_uris_mutex());
      open_uris().erase(claimed_);
    }
  }

  static Expected<std::unique_ptr<InputSource>> open(const std::string& uri, const OpenNISettings& settings) {
    if (ends_with_ignoring_case(uri, ".oni")) MRGI_TRY(probe_file(uri, settings));
    return open_unprobed(uri, settings);
  }

  static Expected<std::unique_ptr<InputSource>> open_unprobed(const std::string& uri,
                                                              const OpenNISettings& settings) {
    auto src = std::unique_ptr<OpenNISource>(new OpenNISource());
    MRGI_TRY(src->open_device(uri, settings));
    return std::unique_ptr<InputSource>(std::move(src));
  }

  // OpenNI2's file driver trusts the recording: one changed property value (a mode count larger
  // than its mode list, say) makes it read out of bounds and segfault inside Device::open, and
  // mrgi's record-structure check (oni_file_inspector.h) cannot know the meaning of every driver
  // property. So the driver first reads the whole file in a child process: the same open and
  // every frame, as this process will read them. A child killed by a signal or past its time
  // limit means the file is refused here, before this process hands it to the driver; a child
  // that ends with an error (a refusal with a message) or with every frame read lets the normal
  // open run, which gives that message itself. Cost: one extra read of the recording at open
  // (0.2 s for the 12-frame Kinect file).
  static Status probe_file(const std::string& uri, const OpenNISettings& settings) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(uri, ec)) return ok_status();  // the open names the problem
    const auto bytes = std::filesystem::file_size(uri, ec);
    // 20 s plus 1 s per 10 MB: the driver decodes ~100 MB/s here; a hang is a refusal, not a wait.
    const auto limit = std::chrono::seconds(20 + (ec ? 0 : int64_t(bytes / 10000000)));
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) return ok_status();  // no probe possible (process limit): open as before
    if (pid == 0) {
      auto src = open_unprobed(uri, settings);
      if (!src.ok()) ::_exit(3);
      for (;;) {
        auto f = (*src)->next(std::chrono::milliseconds(5000));
        if (!f.ok()) ::_exit(f.error().kind == ErrorKind::EndOfStream ? 0 : 3);
      }
    }
    const auto deadline = Clock::now() + limit;
    int status = 0;
    for (;;) {
      const pid_t r = ::waitpid(pid, &status, WNOHANG);
      if (r == pid) break;
      if (r < 0) return ok_status();
      if (Clock::now() > deadline) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        return fail(ErrorKind::BadInput, uri + ": OpenNI2's file driver did not finish reading the recording within " +
                                             std::to_string(limit.count()) +
                                             " s in a probe process (it hangs on this file); refused");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (WIFSIGNALED(status)) {
      const int sig = WTERMSIG(status);
      return fail(ErrorKind::BadInput, uri + ": OpenNI2's file driver crashed (signal " + std::to_string(sig) + ", " +
                                           strsignal(sig) +
                                           ") reading the recording in a probe process: the file is corrupt in a way "
                                           "the record-structure check does not see (for example a property value "
                                           "the driver trusts); refused");
    }
    // The probe ends with 0 (read to the end) or 3 (an error the open in this process reports by
    // name); anything else is a death the driver caused that did not show as a signal (a crash
    // handler that exits, e.g. a sanitizer's): refused too, never retried in this process.
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 3)
      return fail(ErrorKind::BadInput, uri + ": OpenNI2's file driver crashed the probe process (it exited with "
                                           "status " + std::to_string(WEXITSTATUS(status)) +
                                           " through a crash handler) reading the recording: the file is "
                                           "corrupt in a way the record-structure check does not see; refused");
    return ok_status();
  }

  std::string name() const override { return name_; }
  const CaptureInfo& info() const override { return info_; }
  const OpenNIStreamReport& report() const { return report_; }

  Expected<InputFrame> next(std::chrono::milliseconds timeout) override {
    if (report_.is_file && color_read_ >= report_.color_frames_in_file &&
        depth_read_ >= report_.depth_frames_in_file)
      return fail(ErrorKind::EndOfStream, name_ + ": all " + std::to_string(color_read_) +
                                              " colour and " + std::to_string(depth_read_) + " depth frames read");
    const auto deadline = Clock::now() + timeout;
    bool got_color = false, got_depth = false;
    while (!(got_color && got_depth)) {
      // A stream that has delivered all its frames keeps its last image for the pairing.
      const bool color_done = report_.is_file && color_read_ >= report_.color_frames_in_file;
      const bool depth_done = report_.is_file && depth_read_ >= report_.depth_frames_in_file;
      if (color_done) got_color = true;
      if (depth_done) got_depth = true;
      if (got_color && got_depth) break;
      openni::VideoStream* waiting[2];
      int n = 0;
      if (!got_color) waiting[n++] = &color_;
      if (!got_depth) waiting[n++] = &depth_;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      int ready = -1;
      const openni::Status st = openni::OpenNI::waitForAnyStream(waiting, n, &ready, int(std::max<int64_t>(0, left.count())));
      if (st == openni::STATUS_TIME_OUT || (st == openni::STATUS_OK && ready < 0)) {
        if (Clock::now() < deadline) continue;
        return stalled();
      }
      if (st != openni::STATUS_OK)
        return fail(ErrorKind::Device, name_ + ": waiting for frames failed (device unplugged?): " + openni_error_text());
      openni::VideoStream* s = waiting[ready];
      openni::VideoFrameRef f;
      if (s->readFrame(&f) != openni::STATUS_OK)
        return fail(ErrorKind::Device, name_ + ": readFrame failed: " + openni_error_text());
      last_delivery_ = Clock::now();
      if (s == &color_) {
        MRGI_TRY(copy_color(f));
        ++color_read_;
        got_color = true;
      } else {
        MRGI_TRY(copy_depth(f));
        ++depth_read_;
        got_depth = true;
      }
    }
    InputFrame out;
    out.index = emitted_++;
    out.timestamp = color_timestamp_;
    out.depth_timestamp = depth_timestamp_;
    out.color = color_image_;
    out.depth = depth_image_;
    return out;
  }

 private:
  OpenNISource() = default;

  Status open_device(const std::string& uri, const OpenNISettings& settings) {
    MRGI_TRY(openni_initialize());
    settings_ = settings;
    const bool is_file = ends_with_ignoring_case(uri, ".oni");
    report_.is_file = is_file;
    name_ = "openni:" + uri;
    oni::FileSummary summary;
    if (is_file) {
      if (!std::filesystem::exists(uri)) return fail(ErrorKind::NotFound, uri + ": no such OpenNI file");
      // A folder gave std::bad_alloc inside the inspection, a FIFO would block the open.
      std::error_code ec;
      if (!std::filesystem::is_regular_file(uri, ec))
        return fail(ErrorKind::BadInput, uri + ": not a regular file (an .oni recording is a file)");
      // OpenNI2's file driver refuses a truncated file with no message and can stall on a broken
      // one, so the record structure is checked first to give the reason.
      auto s = oni::inspect_oni_file(uri);
      if (!s.ok()) return s.error();
      summary = std::move(s.value());
    }
    {
      std::error_code ec;
      const std::string key = is_file ? std::filesystem::weakly_canonical(uri, ec).string() : uri;
      std::lock_guard<std::mutex> lock(open_uris_mutex());
      if (!key.empty() && !open_uris().insert(key).second)
        return fail(ErrorKind::Device, name_ + ": already open in this process (OpenNI2 would share one playback "
                                               "between both; close the other source first)");
      claimed_ = key;
    }
    if (device_.open(uri.empty() ? openni::ANY_DEVICE : uri.c_str()) != openni::STATUS_OK) {
      if (is_file) return fail(ErrorKind::BadInput, uri + ": OpenNI2's file driver refused the file: " + openni_error_text());
      if (uri.empty()) return fail(ErrorKind::NotFound, "openni: no OpenNI2 device found: " + openni_error_text());
      return fail(ErrorKind::NotFound, "openni: cannot open device '" + uri + "': " + openni_error_text());
    }
    if (is_file) {
      openni::PlaybackControl* pc = device_.getPlaybackControl();
      if (!pc) return fail(ErrorKind::Internal, uri + ": OpenNI2 gave no playback control for a file");
      pc->setRepeatEnabled(false);
      pc->setSpeed(-1.0f);  // as fast as possible: frames are stepped by reading, not by the clock
    }
    if (!device_.hasSensor(openni::SENSOR_DEPTH))
      return fail(ErrorKind::BadInput, name_ + ": has no depth stream (mrgi needs colour and depth)");
    if (!device_.hasSensor(openni::SENSOR_COLOR))
      return fail(ErrorKind::BadInput, name_ + ": has no colour stream (mrgi needs colour and depth)");
    if (depth_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK)
      return fail(ErrorKind::Device, name_ + ": cannot create the depth stream: " + openni_error_text());
    if (color_.create(device_, openni::SENSOR_COLOR) != openni::STATUS_OK)
      return fail(ErrorKind::Device, name_ + ": cannot create the colour stream: " + openni_error_text());

    if (!is_file) {
      MRGI_TRY(choose_mode(depth_, openni::PIXEL_FORMAT_DEPTH_1_MM, "depth"));
      MRGI_TRY(choose_mode(color_, openni::PIXEL_FORMAT_RGB888, "colour"));
      depth_.setMirroringEnabled(false);
      color_.setMirroringEnabled(false);
      if (settings.register_depth_to_color &&
          device_.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) &&
          device_.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) == openni::STATUS_OK) {
        report_.registered = true;
        report_.registration_source = "device registration mode set to DEPTH_TO_COLOR";
      } else {
        report_.registration_source = "device does not support DEPTH_TO_COLOR registration";
      }
      device_.setDepthColorSyncEnabled(true);
    } else {
      openni::PlaybackControl* pc = device_.getPlaybackControl();
      report_.depth_frames_in_file = pc->getNumberOfFrames(depth_);
      report_.color_frames_in_file = pc->getNumberOfFrames(color_);
      if (report_.depth_frames_in_file <= 0 || report_.color_frames_in_file <= 0)
        return fail(ErrorKind::BadInput, uri + ": the file lists " + std::to_string(report_.depth_frames_in_file) +
                                             " depth and " + std::to_string(report_.color_frames_in_file) +
                                             " colour frames (both must be > 0)");
      // The recording is what it is: OpenNI 2 files carry the device's registration mode, OpenNI
      // 1.x files the depth node's AlternativeViewPoint flag (not exposed by OpenNI2's API).
      if (device_.getImageRegistrationMode() == openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) {
        report_.registered = true;
        report_.registration_source = "file's device registration mode";
      } else if (summary.int_property(summary.depth_node, "AlternativeViewPoint", 0) != 0) {
        report_.registered = true;
        report_.registration_source = "file's depth node AlternativeViewPoint = 1 (OpenNI 1.x recording)";
      } else {
        report_.registration_source = "file records no depth-to-colour registration";
      }
      mirror_depth_ = summary.int_property(summary.depth_node, "Mirror", 0) != 0;
      mirror_color_ = summary.int_property(summary.image_node, "Mirror", 0) != 0;
    }
    mirror_depth_ = mirror_depth_ || depth_.getMirroringEnabled();
    mirror_color_ = mirror_color_ || color_.getMirroringEnabled();
    report_.mirrored = mirror_depth_ || mirror_color_;

    const openni::VideoMode dm = depth_.getVideoMode(), cm = color_.getVideoMode();
    if (dm.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM) {
      info_.depth_scale = 1000.0;
    } else if (dm.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM) {
      info_.depth_scale = 10000.0;
    } else {
      return fail(ErrorKind::BadInput, name_ + ": depth pixel format " + std::to_string(int(dm.getPixelFormat())) +
                                           " is not supported (needs DEPTH_1_MM or DEPTH_100_UM)");
    }
    if (cm.getPixelFormat() != openni::PIXEL_FORMAT_RGB888)
      return fail(ErrorKind::BadInput, name_ + ": colour pixel format " + std::to_string(int(cm.getPixelFormat())) +
                                           " is not supported (needs RGB888)");
    if (!fov_valid(depth_.getHorizontalFieldOfView(), depth_.getVerticalFieldOfView()))
      return fail(ErrorKind::BadInput, name_ + ": the depth stream reports no valid field of view (hfov " +
                                           std::to_string(depth_.getHorizontalFieldOfView()) + " rad)");
    info_.depth = intrinsics_from_fov(dm.getResolutionX(), dm.getResolutionY(), depth_.getHorizontalFieldOfView(),
                                      depth_.getVerticalFieldOfView());
    if (fov_valid(color_.getHorizontalFieldOfView(), color_.getVerticalFieldOfView())) {
      info_.color = intrinsics_from_fov(cm.getResolutionX(), cm.getResolutionY(), color_.getHorizontalFieldOfView(),
                                        color_.getVerticalFieldOfView());
      report_.color_fov_source = "colour stream";
    } else {
      // Registered depth is in the colour camera's geometry, so its field of view is the colour
      // camera's; unregistered, it is only the closest estimate there is, and the report says so.
      info_.color = info_.depth.scaled_to(cm.getResolutionX(), cm.getResolutionY());
      report_.color_fov_source = report_.registered
                                     ? "depth stream (colour stream reports none; depth is registered to colour)"
                                     : "depth stream (colour stream reports none; depth is NOT registered: estimate)";
    }
    if (report_.registered) info_.depth = info_.color.scaled_to(dm.getResolutionX(), dm.getResolutionY());
    color_image_ = ImageRGB8(cm.getResolutionX(), cm.getResolutionY());
    depth_image_ = ImageU16(dm.getResolutionX(), dm.getResolutionY());

    // Both streams are started before any read: the file driver blocks for ever on a created
    // stream that is never started.
    if (depth_.start() != openni::STATUS_OK)
      return fail(ErrorKind::Device, name_ + ": cannot start the depth stream: " + openni_error_text());
    if (color_.start() != openni::STATUS_OK)
      return fail(ErrorKind::Device, name_ + ": cannot start the colour stream: " + openni_error_text());
    last_delivery_ = Clock::now();
    return ok_status();
  }

  Status choose_mode(openni::VideoStream& s, openni::PixelFormat format, const char* what) {
    const auto& modes = s.getSensorInfo().getSupportedVideoModes();
    int best = -1;
    long best_cost = 0;
    for (int i = 0; i < modes.getSize(); ++i) {
      if (modes[i].getPixelFormat() != format) continue;
      const long cost = std::labs(modes[i].getResolutionX() - settings_.width) +
                        std::labs(modes[i].getResolutionY() - settings_.height) +
                        10 * std::labs(modes[i].getFps() - settings_.fps);
      if (best < 0 || cost < best_cost) best = i, best_cost = cost;
    }
    if (best < 0)
      return fail(ErrorKind::BadInput, name_ + ": the " + what + " sensor offers no mode in pixel format " +
                                           std::to_string(int(format)) + " (unsupported format)");
    if (s.setVideoMode(modes[best]) != openni::STATUS_OK)
      return fail(ErrorKind::Device, name_ + ": cannot set the " + what + " mode: " + openni_error_text());
    return ok_status();
  }

  Error stalled() const {
    const auto quiet = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - last_delivery_).count();
    if (report_.is_file && quiet >= settings_.playback_stall_ms)
      return fail(ErrorKind::BadInput, name_ + ": playback stopped delivering after colour frame " +
                                           std::to_string(color_read_) + "/" + std::to_string(report_.color_frames_in_file) +
                                           " and depth frame " + std::to_string(depth_read_) + "/" +
                                           std::to_string(report_.depth_frames_in_file) + " for " +
                                           std::to_string(quiet) + " ms (corrupt frame data)");
    return fail(ErrorKind::Timeout, name_ + ": no frame within the wait (" + std::to_string(quiet) +
                                        " ms since the last one)");
  }

  Status check_size(const openni::VideoFrameRef& f, int w, int h, const char* what) const {
    if (f.getWidth() != w || f.getHeight() != h)
      return fail(ErrorKind::BadInput, name_ + ": " + what + " frame " + std::to_string(f.getFrameIndex()) + " is " +
                                           std::to_string(f.getWidth()) + "x" + std::to_string(f.getHeight()) +
                                           ", the stream's mode is " + std::to_string(w) + "x" + std::to_string(h));
    return ok_status();
  }

  Status copy_color(const openni::VideoFrameRef& f) {
    MRGI_TRY(check_size(f, color_image_.width, color_image_.height, "colour"));
    const int w = color_image_.width, h = color_image_.height, stride = f.getStrideInBytes();
    if (stride < w * 3 || f.getDataSize() < stride * h)
      return fail(ErrorKind::BadInput, name_ + ": colour frame " + std::to_string(f.getFrameIndex()) + " holds " +
                                           std::to_string(f.getDataSize()) + " bytes, too few for its size");
    const auto* src = static_cast<const uint8_t*>(f.getData());
    for (int y = 0; y < h; ++y) {
      const uint8_t* row = src + size_t(y) * stride;
      uint8_t* dst = color_image_.at(0, y);
      if (!mirror_color_) {
        std::memcpy(dst, row, size_t(w) * 3);
      } else {
        for (int x = 0; x < w; ++x) std::memcpy(dst + 3 * x, row + 3 * (w - 1 - x), 3);
      }
    }
    color_timestamp_ = double(f.getTimestamp()) * 1e-6;
    return ok_status();
  }

  Status copy_depth(const openni::VideoFrameRef& f) {
    MRGI_TRY(check_size(f, depth_image_.width, depth_image_.height, "depth"));
    const int w = depth_image_.width, h = depth_image_.height, stride = f.getStrideInBytes();
    if (stride < w * 2 || f.getDataSize() < stride * h)
      return fail(ErrorKind::BadInput, name_ + ": depth frame " + std::to_string(f.getFrameIndex()) + " holds " +
                                           std::to_string(f.getDataSize()) + " bytes, too few for its size");
    const auto* src = static_cast<const uint8_t*>(f.getData());
    for (int y = 0; y < h; ++y) {
      const auto* row = reinterpret_cast<const uint16_t*>(src + size_t(y) * stride);
      uint16_t* dst = depth_image_.at(0, y);
      if (!mirror_depth_) {
        std::memcpy(dst, row, size_t(w) * 2);
      } else {
        for (int x = 0; x < w; ++x) dst[x] = row[w - 1 - x];
      }
    }
    depth_timestamp_ = double(f.getTimestamp()) * 1e-6;
    return ok_status();
  }

  std::string name_;
  std::string claimed_;  // key in open_uris(), released on destruction
  OpenNISettings settings_;
  CaptureInfo info_;
  OpenNIStreamReport report_;
  openni::Device device_;
  openni::VideoStream depth_, color_;
  bool mirror_depth_ = false, mirror_color_ = false;
  ImageRGB8 color_image_;
  ImageU16 depth_image_;
  double color_timestamp_ = 0.0, depth_timestamp_ = 0.0;
  int color_read_ = 0, depth_read_ = 0;
  int64_t emitted_ = 0;
  Clock::time_point last_delivery_;
};

}  // namespace

Status openni_initialize() {
  static std::once_flag once;
  static Status result = ok_status();
  std::call_once(once, [] {
    if (openni::OpenNI::initialize() != openni::STATUS_OK)
      result = fail(ErrorKind::Device, std::string("openni: OpenNI2 initialisation failed (drivers are looked up in "
                                                   "OpenNI2/Drivers next to libOpenNI2.so, per /etc/openni2/OpenNI.ini): ") +
                                           openni_error_text());
  });
  return result;
}

Expected<std::vector<OpenNIDeviceEntry>> list_openni_devices() {
  MRGI_TRY(openni_initialize());
  openni::Array<openni::DeviceInfo> list;
  openni::OpenNI::enumerateDevices(&list);
  std::vector<OpenNIDeviceEntry> out;
  for (int i = 0; i < list.getSize(); ++i)
    out.push_back({list[i].getUri(), list[i].getName(), list[i].getVendor(), list[i].getUsbVendorId(),
                   list[i].getUsbProductId()});
  return out;
}

Expected<std::unique_ptr<InputSource>> open_openni_source(const std::string& uri, const OpenNISettings& settings) {
  return OpenNISource::open(uri, settings);
}

const OpenNIStreamReport* openni_report(const InputSource& source) {
  const auto* s = dynamic_cast<const OpenNISource*>(&source);
  return s ? &s->report() : nullptr;
}

}  // namespace mrgi
