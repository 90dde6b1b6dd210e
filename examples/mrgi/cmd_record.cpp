// mrgi record SOURCE --out CAPTURE [--frames N]: records any input source (openni:FILE.oni,
// openni:, v4l2:/dev/videoN, libcamera:ID, or a capture folder) to capture format v1, which
// `mrgi replay` reads back unchanged.
#include <iostream>

#include "commands.h"
#include "mrgi/platform/devices.h"

namespace mrgi::tool {
namespace {

struct RecordOptions {
  std::string source, out;
  int frames = 0;
  int timeout_ms = 3000;
  bool quiet = false;
};

void run_record(const RecordOptions& o) {
  auto source = take(open_source(o.source, SourceOptions{}));
  RecordSettings s;
  s.max_frames = size_t(o.frames);
  s.timeout = std::chrono::milliseconds(o.timeout_ms);
  const size_t n = take(record_to_capture(*source, o.out, s));
  if (!o.quiet) std::cerr << "mrgi record: " << n << " frames from " << source->name() << " -> " << o.out << "\n";
  std::cout << "{\"frames\": " << n << ", \"capture\": \"" << o.out << "\"}\n";
}

void setup(CLI::App& app) {
  auto o = std::make_shared<RecordOptions>();
  CLI::App* cmd = app.add_subcommand("record", "Record an input source to a capture folder (format v1)");
  cmd->add_option("source", o->source, "openni:, openni:FILE.oni, v4l2:/dev/videoN, libcamera:ID or a capture folder")->required();
  cmd->add_option("--out,-o", o->out, "capture folder to create (must not exist)")->required();
  cmd->add_option("--frames,-n", o->frames, "record at most N frames (0 = until the stream ends)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--timeout-ms", o->timeout_ms, "longest wait for one frame before failing (ms)")->check(CLI::Range(1, 600000))->capture_default_str();
  cmd->add_flag("--quiet,-q", o->quiet, "no summary on stderr");
  cmd->callback([o] { run_record(*o); });
}

}  // namespace

MRGI_COMMAND(record, setup);

}  // namespace mrgi::tool
