// libcamera backend: requests complete on libcamera's own thread; the slot only queues the
// request, and dequeue() waits on a condition variable with the caller's timeout.
#include <sys/mman.h>

#include <cstdlib>

#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/logging.h>
#include <libcamera/property_ids.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include "common/camera_stream.h"
#include "mrgi/platform/libcamera.h"

namespace mrgi {
namespace {

namespace lc = libcamera;

// libcamera allows one CameraManager per process; it lives until exit.
Expected<lc::CameraManager*> camera_manager() {
  static std::mutex m;
  static std::unique_ptr<lc::CameraManager> manager;
  static int start_result = 1;
  std::lock_guard<std::mutex> lock(m);
  if (start_result == 1) {
    // libcamera logs INFO/WARN lines (e.g. "No IPA found") to stderr; keep errors only unless
    // the user asked for more.
    if (!std::getenv("LIBCAMERA_LOG_LEVELS")) setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0);
    manager = std::make_unique<lc::CameraManager>();
    start_result = manager->start();
  }
  if (start_result != 0)
    return fail(ErrorKind::Device, "libcamera: CameraManager::start failed: " + std::string(std::strerror(-start_result)));
  return manager.get();
}

class LibcameraBackend final : public CameraBackend {
 public:
  explicit LibcameraBackend(std::string id) : id_(std::move(id)) {}
  ~LibcameraBackend() override {
    stop();
    close();
  }
  std::string name() const override { return "libcamera:" + id_; }

  Status open() override {
    auto mgr = camera_manager();
    if (!mgr.ok()) return mgr.error();
    auto cams = (*mgr)->cameras();
    if (cams.empty()) return fail(ErrorKind::NotFound, name() + ": libcamera manages no camera on this machine");
    if (id_.empty()) id_ = cams.front()->id();
    camera_ = (*mgr)->get(id_);
    if (!camera_) {
      std::string ids;
      for (auto& c : cams) ids += (ids.empty() ? "" : ", ") + c->id();
      return fail(ErrorKind::NotFound, name() + ": no such camera (libcamera has: " + ids + ")");
    }
    if (camera_->acquire() != 0) {
      camera_.reset();
      return fail(ErrorKind::Device, name() + ": cannot acquire the camera (in use by another process?)");
    }
    acquired_ = true;
    camera_->disconnected.connect(this, &LibcameraBackend::on_disconnected);
    config_ = camera_->generateConfiguration({lc::StreamRole::VideoRecording});
    if (!config_ || config_->empty()) return fail(ErrorKind::Device, name() + ": generateConfiguration gave nothing");
    return ok_status();
  }

  Expected<OfferedFormats> formats() override {
    OfferedFormats out;
    const lc::StreamFormats& sf = config_->at(0).formats();
    for (const lc::PixelFormat& pf : sf.pixelformats()) {
      auto f = pixel_format_from_libcamera(pf.toString());
      if (!f) {
        out.unsupported.push_back(pf.toString());
        continue;
      }
      for (const lc::Size& s : sf.sizes(pf)) out.supported.push_back({*f, int(s.width), int(s.height)});
    }
    return out;
  }

  Expected<FormatOption> configure(const FormatOption& wanted, const CameraSettings& settings) override {
    lc::StreamConfiguration& cfg = config_->at(0);
    cfg.pixelFormat = libcamera_format(wanted.format);
    cfg.size = lc::Size(unsigned(wanted.width), unsigned(wanted.height));
    cfg.bufferCount = unsigned(settings.buffer_count);
    if (config_->validate() == lc::CameraConfiguration::Invalid)
      return fail(ErrorKind::BadInput, name() + ": unsupported format: libcamera rejects " + to_string(wanted.format) + " " +
                                           std::to_string(wanted.width) + "x" + std::to_string(wanted.height));
    auto got = pixel_format_from_libcamera(cfg.pixelFormat.toString());
    if (!got)
      return fail(ErrorKind::BadInput, name() + ": unsupported format: libcamera adjusted the format to " + cfg.pixelFormat.toString());
    if (camera_->configure(config_.get()) != 0) return fail(ErrorKind::Device, name() + ": Camera::configure failed");
    stream_ = cfg.stream();
    stride_ = int(cfg.stride);
    format_ = {*got, int(cfg.size.width), int(cfg.size.height)};
    allocator_ = std::make_unique<lc::FrameBufferAllocator>(camera_);
    if (allocator_->allocate(stream_) < 0) return fail(ErrorKind::Device, name() + ": buffer allocation failed");
    for (const auto& buffer : allocator_->buffers(stream_)) {
      std::unique_ptr<lc::Request> req = camera_->createRequest();
      if (!req || req->addBuffer(stream_, buffer.get()) != 0)
        return fail(ErrorKind::Device, name() + ": cannot create a request");
      MRGI_TRY(map_buffer(buffer.get()));
      requests_.push_back(std::move(req));
    }
    const size_t frame_bytes = size_t(stride_ ? stride_ : format_.width * 3) * size_t(format_.height) * 2;
    scratch_.resize(frame_bytes);
    return format_;
  }

  Status start() override {
    camera_->requestCompleted.connect(this, &LibcameraBackend::on_completed);
    if (camera_->start() != 0) return fail(ErrorKind::Device, name() + ": Camera::start failed");
    started_ = true;
    for (auto& r : requests_)
      if (camera_->queueRequest(r.get()) != 0) return fail(ErrorKind::Device, name() + ": queueRequest failed");
    return ok_status();
  }

  Expected<RawFrame> dequeue(std::chrono::milliseconds timeout) override {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return !completed_.empty() || disconnected_; });
    if (disconnected_) return fail(ErrorKind::Device, name() + ": camera disconnected (unplugged)");
    if (completed_.empty())
      return fail(ErrorKind::Timeout, name() + ": no frame within " + std::to_string(timeout.count()) + " ms");
    held_ = completed_.front();
    completed_.pop_front();
    lock.unlock();
    if (held_->status() != lc::Request::RequestComplete)
      return fail(ErrorKind::Device, name() + ": request failed (status " + std::to_string(int(held_->status())) + ")");
    lc::FrameBuffer* buffer = held_->findBuffer(stream_);
    const auto& planes = buffer->planes();
    const auto& meta = buffer->metadata();
    RawFrame f;
    f.format = format_.format;
    f.width = format_.width;
    f.height = format_.height;
    f.stride = format_.format == PixelFormat::MJPEG ? 0 : stride_;
    f.timestamp = double(meta.timestamp) * 1e-9;
    f.sequence = meta.sequence;
    // Planes may live at any offset of any dmabuf; multi-plane frames are gathered into one
    // contiguous scratch buffer (allocated once at configure time).
    if (planes.size() == 1) {
      f.data = plane_pointer(planes[0]);
      f.size = std::min<size_t>(meta.planes()[0].bytesused, planes[0].length);
    } else {
      size_t at = 0;
      for (size_t i = 0; i < planes.size(); ++i) {
        const size_t n = std::min<size_t>(meta.planes()[i].bytesused, planes[i].length);
        if (at + n > scratch_.size()) return fail(ErrorKind::Device, name() + ": plane sizes exceed the frame size");
        std::memcpy(scratch_.data() + at, plane_pointer(planes[i]), n);
        at += n;
      }
      f.data = scratch_.data();
      f.size = at;
    }
    return f;
  }

  Status release() override {
    if (!held_) return ok_status();
    lc::Request* r = held_;
    held_ = nullptr;
    r->reuse(lc::Request::ReuseBuffers);
    if (camera_->queueRequest(r) != 0) return fail(ErrorKind::Device, name() + ": queueRequest failed (unplugged?)");
    return ok_status();
  }

  void stop() override {
    if (!started_) return;
    camera_->stop();
    camera_->requestCompleted.disconnect(this);
    started_ = false;
  }

  void close() override {
    for (auto& [fd, m] : maps_) munmap(m.first, m.second);
    maps_.clear();
    requests_.clear();
    if (allocator_ && stream_) allocator_->free(stream_);
    allocator_.reset();
    if (camera_) {
      camera_->disconnected.disconnect(this);
      if (acquired_) camera_->release();
    }
    acquired_ = false;
    camera_.reset();
  }

 private:
  static lc::PixelFormat libcamera_format(PixelFormat f) {
    switch (f) {
      case PixelFormat::YUYV: return lc::formats::YUYV;
      case PixelFormat::UYVY: return lc::formats::UYVY;
      case PixelFormat::RGB24: return lc::formats::BGR888;  // DRM naming: memory order R,G,B
      case PixelFormat::BGR24: return lc::formats::RGB888;
      case PixelFormat::NV12: return lc::formats::NV12;
      case PixelFormat::MJPEG: return lc::formats::MJPEG;
    }
    return lc::formats::YUYV;
  }

  Status map_buffer(const lc::FrameBuffer* buffer) {
    for (const auto& p : buffer->planes()) {
      const int fd = p.fd.get();
      size_t end = size_t(p.offset) + p.length;
      auto it = maps_.find(fd);
      if (it != maps_.end() && it->second.second >= end) continue;
      if (it != maps_.end()) {
        munmap(it->second.first, it->second.second);
        maps_.erase(it);
      }
      for (const auto& q : buffer->planes())
        if (q.fd.get() == fd) end = std::max(end, size_t(q.offset) + q.length);
      void* mem = mmap(nullptr, end, PROT_READ, MAP_SHARED, fd, 0);
      if (mem == MAP_FAILED) return fail(ErrorKind::Device, name() + ": mmap of a frame buffer failed");
      maps_[fd] = {mem, end};
    }
    return ok_status();
  }

  const uint8_t* plane_pointer(const lc::FrameBuffer::Plane& p) const {
    return static_cast<const uint8_t*>(maps_.at(p.fd.get()).first) + p.offset;
  }

  void on_completed(lc::Request* r) {
    if (r->status() == lc::Request::RequestCancelled) return;
    std::lock_guard<std::mutex> lock(mutex_);
    completed_.push_back(r);
    cv_.notify_one();
  }

  void on_disconnected() {
    std::lock_guard<std::mutex> lock(mutex_);
    disconnected_ = true;
    cv_.notify_one();
  }

  std::string id_;
  std::shared_ptr<lc::Camera> camera_;
  bool acquired_ = false, started_ = false;
  std::unique_ptr<lc::CameraConfiguration> config_;
  lc::Stream* stream_ = nullptr;
  int stride_ = 0;
  FormatOption format_;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<lc::Request>> requests_;
  std::map<int, std::pair<void*, size_t>> maps_;
  std::vector<uint8_t> scratch_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<lc::Request*> completed_;
  bool disconnected_ = false;
  lc::Request* held_ = nullptr;
};

}  // namespace

std::unique_ptr<CameraBackend> make_libcamera_backend(const std::string& camera_id) {
  return std::make_unique<LibcameraBackend>(camera_id);
}

Expected<std::vector<LibcameraEntry>> list_libcamera_cameras() {
  auto mgr = camera_manager();
  if (!mgr.ok()) return mgr.error();
  std::vector<LibcameraEntry> out;
  for (const auto& cam : (*mgr)->cameras()) {
    LibcameraEntry e;
    e.id = cam->id();
    const auto& props = cam->properties();
    if (auto model = props.get(lc::properties::Model)) e.model = *model;
    if (auto loc = props.get(lc::properties::Location))
      e.location = *loc == lc::properties::CameraLocationFront  ? "front"
                   : *loc == lc::properties::CameraLocationBack ? "back"
                                                                : "external";
    out.push_back(e);
  }
  return out;
}

Expected<std::unique_ptr<InputSource>> open_libcamera_source(const std::string& id, const CameraSettings& settings) {
  auto src = CameraStreamSource::open(make_libcamera_backend(id), settings);
  if (!src.ok()) return src.error();
  return std::unique_ptr<InputSource>(std::move(src.value()));
}

}  // namespace mrgi
