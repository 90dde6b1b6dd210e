#include "mrgi/platform/capture_source.h"

#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

class CaptureSource final : public InputSource {
 public:
  explicit CaptureSource(CaptureReader reader) : reader_(std::move(reader)) {}

  std::string name() const override { return "capture:" + reader_.folder(); }
  const CaptureInfo& info() const override { return reader_.info(); }

  // Files are read synchronously, so there is nothing to wait for and the timeout is unused.
  Expected<InputFrame> next(std::chrono::milliseconds) override {
    if (next_ >= reader_.frame_count())
      return fail(ErrorKind::EndOfStream, name() + ": all " + std::to_string(reader_.frame_count()) +
                                              " frames replayed");
    auto frame = reader_.read_frame(next_);
    if (frame) ++next_;
    return frame;
  }

 private:
  CaptureReader reader_;
  size_t next_ = 0;
};

}  // namespace

Expected<std::unique_ptr<InputSource>> make_capture_source(const std::string& folder) {
  auto reader = CaptureReader::open(folder);
  if (!reader) return reader.error();
  return std::unique_ptr<InputSource>(std::make_unique<CaptureSource>(std::move(*reader)));
}

}  // namespace mrgi
