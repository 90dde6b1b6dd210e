// V4L2 through libv4l2: v4l2_open/v4l2_ioctl/v4l2_mmap behave like the raw calls but libv4l adds
// format emulation (e.g. RGB24 for cameras that only send Bayer or vendor formats) and works
// around driver quirks. Streaming is memory-mapped; every wait is a select() with a timeout.
#include <fcntl.h>
#include <libv4l2.h>
#include <linux/videodev2.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "common/camera_stream.h"

namespace mrgi {
namespace {

int xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do r = v4l2_ioctl(fd, request, arg);
  while (r == -1 && errno == EINTR);
  return r;
}

std::string errno_text(int e) { return std::string(std::strerror(e)) + " (errno " + std::to_string(e) + ")"; }

bool is_unplug(int e) { return e == ENODEV || e == EIO || e == ENXIO || e == EBADF; }

class V4L2Backend final : public CameraBackend {
 public:
  explicit V4L2Backend(std::string path) : path_(std::move(path)) {}
  ~V4L2Backend() override {
    stop();
    close();
  }
  std::string name() const override { return "v4l2:" + path_; }

  Status open() override {
    if (!std::filesystem::exists(path_)) return fail(ErrorKind::NotFound, name() + ": no such device node (no V4L2 camera)");
    fd_ = v4l2_open(path_.c_str(), O_RDWR | O_NONBLOCK);
    if (fd_ < 0) {
      const int e = errno;
      return fail(e == ENOENT || e == ENODEV ? ErrorKind::NotFound : ErrorKind::Device,
                  name() + ": cannot open: " + errno_text(e));
    }
    v4l2_capability cap{};
    if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0)
      return fail(ErrorKind::Device, name() + ": VIDIOC_QUERYCAP failed: " + errno_text(errno));
    const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
      return fail(ErrorKind::BadInput, name() + ": not a single-planar video capture device (" +
                                           reinterpret_cast<const char*>(cap.card) + ")");
    if (!(caps & V4L2_CAP_STREAMING))
      return fail(ErrorKind::BadInput, name() + ": the driver has no streaming I/O (memory mapping needed)");
    return ok_status();
  }

  Expected<OfferedFormats> formats() override {
    OfferedFormats out;
    for (uint32_t i = 0;; ++i) {
      v4l2_fmtdesc d{};
      d.index = i;
      d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(fd_, VIDIOC_ENUM_FMT, &d) < 0) break;
      auto f = pixel_format_from_v4l2(d.pixelformat);
      if (!f) {
        out.unsupported.push_back(fourcc_text(d.pixelformat));
        continue;
      }
      bool any_size = false;
      for (uint32_t k = 0;; ++k) {
        v4l2_frmsizeenum s{};
        s.index = k;
        s.pixel_format = d.pixelformat;
        if (xioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &s) < 0) break;
        if (s.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
          out.supported.push_back({*f, int(s.discrete.width), int(s.discrete.height)});
          any_size = true;
        } else {
          break;  // stepwise: the driver adjusts any size in VIDIOC_S_FMT
        }
      }
      if (!any_size) out.supported.push_back({*f, 0, 0});  // 0 = "ask for the requested size"
    }
    return out;
  }

  Expected<FormatOption> configure(const FormatOption& wanted, const CameraSettings& settings) override {
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = uint32_t(wanted.width ? wanted.width : settings.width);
    fmt.fmt.pix.height = uint32_t(wanted.height ? wanted.height : settings.height);
    fmt.fmt.pix.pixelformat = v4l2_fourcc_of(wanted.format);
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_, VIDIOC_S_FMT, &fmt) < 0)
      return fail(ErrorKind::Device, name() + ": VIDIOC_S_FMT " + to_string(wanted.format) + " failed: " + errno_text(errno));
    auto got = pixel_format_from_v4l2(fmt.fmt.pix.pixelformat);
    if (!got)
      return fail(ErrorKind::BadInput, name() + ": unsupported format: the driver answered " +
                                           fourcc_text(fmt.fmt.pix.pixelformat) + " to a request for " + to_string(wanted.format));
    stride_ = int(fmt.fmt.pix.bytesperline);
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_G_PARM, &parm) == 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      parm.parm.capture.timeperframe.numerator = 1000;
      parm.parm.capture.timeperframe.denominator = uint32_t(settings.fps * 1000.0);
      xioctl(fd_, VIDIOC_S_PARM, &parm);  // best effort: the rate is a request, not a contract
    }
    v4l2_requestbuffers req{};
    req.count = uint32_t(settings.buffer_count);
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_REQBUFS, &req) < 0 || req.count < 2)
      return fail(ErrorKind::Device, name() + ": VIDIOC_REQBUFS (memory mapping) failed: " + errno_text(errno));
    for (uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (xioctl(fd_, VIDIOC_QUERYBUF, &b) < 0)
        return fail(ErrorKind::Device, name() + ": VIDIOC_QUERYBUF failed: " + errno_text(errno));
      void* p = v4l2_mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
      if (p == MAP_FAILED) return fail(ErrorKind::Device, name() + ": mmap failed: " + errno_text(errno));
      buffers_.push_back({p, b.length});
    }
    format_ = {*got, int(fmt.fmt.pix.width), int(fmt.fmt.pix.height)};
    return format_;
  }

  Status start() override {
    for (uint32_t i = 0; i < buffers_.size(); ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (xioctl(fd_, VIDIOC_QBUF, &b) < 0) return fail(ErrorKind::Device, name() + ": VIDIOC_QBUF failed: " + errno_text(errno));
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_STREAMON, &type) < 0)
      return fail(ErrorKind::Device, name() + ": VIDIOC_STREAMON failed: " + errno_text(errno));
    streaming_ = true;
    return ok_status();
  }

  Expected<RawFrame> dequeue(std::chrono::milliseconds timeout) override {
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(fd_, &fds);
    timeval tv{long(timeout.count() / 1000), long((timeout.count() % 1000) * 1000)};
    int r;
    do r = select(fd_ + 1, &fds, nullptr, nullptr, &tv);
    while (r == -1 && errno == EINTR);
    if (r == 0) return fail(ErrorKind::Timeout, name() + ": no frame within " + std::to_string(timeout.count()) + " ms");
    if (r < 0) return fail(ErrorKind::Device, name() + ": select failed (device unplugged?): " + errno_text(errno));
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_DQBUF, &b) < 0) {
      const int e = errno;
      if (e == EAGAIN) return fail(ErrorKind::Timeout, name() + ": woke without a filled buffer");
      return fail(ErrorKind::Device, name() + (is_unplug(e) ? ": device unplugged: " : ": VIDIOC_DQBUF failed: ") + errno_text(e));
    }
    held_ = int(b.index);
    RawFrame f;
    f.format = format_.format;
    f.width = format_.width;
    f.height = format_.height;
    f.stride = format_.format == PixelFormat::MJPEG ? 0 : stride_;
    f.data = static_cast<const uint8_t*>(buffers_[b.index].start);
    f.size = std::min<size_t>(b.bytesused, buffers_[b.index].length);
    f.timestamp = double(b.timestamp.tv_sec) + 1e-6 * double(b.timestamp.tv_usec);
    f.sequence = b.sequence;
    return f;
  }

  Status release() override {
    if (held_ < 0) return ok_status();
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = uint32_t(held_);
    held_ = -1;
    if (xioctl(fd_, VIDIOC_QBUF, &b) < 0)
      return fail(ErrorKind::Device, name() + ": VIDIOC_QBUF failed (device unplugged?): " + errno_text(errno));
    return ok_status();
  }

  void stop() override {
    if (!streaming_) return;
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }

  void close() override {
    for (auto& b : buffers_) v4l2_munmap(b.start, b.length);
    buffers_.clear();
    if (fd_ >= 0) v4l2_close(fd_);
    fd_ = -1;
  }

 private:
  struct Mapped {
    void* start;
    size_t length;
  };
  std::string path_;
  int fd_ = -1;
  bool streaming_ = false;
  int stride_ = 0;
  int held_ = -1;
  FormatOption format_;
  std::vector<Mapped> buffers_;
};

}  // namespace

std::vector<V4L2NodeEntry> list_v4l2_nodes() {
  std::vector<V4L2NodeEntry> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("video", 0) != 0) continue;
    V4L2NodeEntry node;
    node.path = e.path().string();
    const int fd = v4l2_open(node.path.c_str(), O_RDWR | O_NONBLOCK);
    if (fd < 0) {
      node.error = errno_text(errno);
      out.push_back(node);
      continue;
    }
    v4l2_capability cap{};
    if (xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0) {
      node.driver = reinterpret_cast<const char*>(cap.driver);
      node.card = reinterpret_cast<const char*>(cap.card);
      node.bus_info = reinterpret_cast<const char*>(cap.bus_info);
      const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
      node.capture = (caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING);
      for (uint32_t i = 0; node.capture; ++i) {
        v4l2_fmtdesc d{};
        d.index = i;
        d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(fd, VIDIOC_ENUM_FMT, &d) < 0) break;
        V4L2FormatEntry f;
        f.fourcc = fourcc_text(d.pixelformat);
        f.supported = pixel_format_from_v4l2(d.pixelformat).has_value();
        f.emulated = d.flags & V4L2_FMT_FLAG_EMULATED;
        for (uint32_t k = 0;; ++k) {
          v4l2_frmsizeenum s{};
          s.index = k;
          s.pixel_format = d.pixelformat;
          if (xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s) < 0 || s.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
          f.sizes.emplace_back(int(s.discrete.width), int(s.discrete.height));
        }
        node.formats.push_back(f);
      }
    } else {
      node.error = "VIDIOC_QUERYCAP failed: " + errno_text(errno);
    }
    v4l2_close(fd);
    out.push_back(node);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
  return out;
}

std::unique_ptr<CameraBackend> make_v4l2_backend(const std::string& device) {
  return std::make_unique<V4L2Backend>(device);
}

Expected<std::unique_ptr<InputSource>> open_v4l2_source(const std::string& device, const CameraSettings& settings) {
  auto src = CameraStreamSource::open(make_v4l2_backend(device), settings);
  if (!src.ok()) return src.error();
  return std::unique_ptr<InputSource>(std::move(src.value()));
}

}  // namespace mrgi
