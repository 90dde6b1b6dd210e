#include <filesystem>

#include "mrgi/platform/devices.h"

namespace mrgi {

Expected<size_t> record_to_capture(InputSource& source, const std::string& folder, const RecordSettings& settings) {
  auto writer = CaptureWriter::create(folder, source.info(), std::nullopt);
  if (!writer.ok()) return writer.error();
  size_t frames = 0;
  auto abandon = [&](const Error& e) -> Error {
    std::error_code ec;
    std::filesystem::remove_all(std::filesystem::path(folder).lexically_normal().string() + ".partial", ec);
    return fail(e.kind, "recording " + source.name() + " to " + folder + ", frame " + std::to_string(frames) + ": " +
                            e.message + " (nothing written)");
  };
  while (settings.max_frames == 0 || frames < settings.max_frames) {
    auto f = source.next(settings.timeout);
    if (!f.ok()) {
      if (f.error().kind == ErrorKind::EndOfStream) break;
      return abandon(f.error());
    }
    auto st = writer->add_frame(*f);
    if (!st.ok()) return abandon(st.error());
    ++frames;
  }
  if (frames == 0) return abandon(fail(ErrorKind::BadInput, "the source delivered no frame"));
  auto st = writer->finish();
  if (!st.ok()) return abandon(st.error());
  return frames;
}

}  // namespace mrgi
