// mrgi references CAPTURE (--export DIR | --convert delta|plain): the ground-truth reference
// frames of a capture. References may be stored as deltas from the camera frame
// (reference/NNNNNN.delta.png, mrgi/platform/capture_references.h), which image viewers cannot
// show; --export writes them as plain PNGs, --convert rewrites the capture's own storage in place
// (verified lossless, frame by frame).
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_references.h"

namespace mrgi::tool {
namespace {

struct ReferencesArgs {
  std::string capture, export_dir, convert;
};

void run_references(const ReferencesArgs& a) {
  if (a.export_dir.empty() == a.convert.empty())
    fail_with(fail(ErrorKind::BadUsage, "mrgi references: give exactly one of --export DIR or --convert delta|plain"));
  if (!a.export_dir.empty()) {
    const CaptureReader capture = take(CaptureReader::open(a.capture));
    const size_t written = take(export_references(capture, a.export_dir));
    std::printf("references: wrote %zu reference frames of %s to %s (NNNNNN.png = frame index)\n", written,
                a.capture.c_str(), a.export_dir.c_str());
    return;
  }
  const ReferenceStorage to = a.convert == "plain" ? ReferenceStorage::Plain : ReferenceStorage::Delta;
  const ReferenceConversion r = take(convert_capture_references(a.capture, to));
  std::printf("references: %s: %zu converted to %s (each read back and checked equal to the original), "
              "%zu already %s\n",
              a.capture.c_str(), r.converted, a.convert.c_str(), r.unchanged, a.convert.c_str());
}

void setup(CLI::App& app) {
  auto args = std::make_shared<ReferencesArgs>();
  CLI::App* cmd = app.add_subcommand(
      "references", "Export a capture's reference frames as plain PNGs, or convert how the capture stores them");
  cmd->add_option("capture", args->capture, "capture folder (capture format v1) with reference.txt")->required();
  cmd->add_option("--export", args->export_dir,
                  "write every reference as a plain 8-bit PNG DIR/NNNNNN.png (NNNNNN = frame index); DIR "
                  "must be new or empty");
  cmd->add_option("--convert", args->convert,
                  "rewrite the capture's references in place: delta (reference/NNNNNN.delta.png, "
                  "(reference - rgb) mod 256) or plain (reference/NNNNNN.png)")
      ->check(CLI::IsMember({"delta", "plain"}));
  cmd->callback([args] { run_references(*args); });
}

}  // namespace
MRGI_COMMAND(references, setup);
}  // namespace mrgi::tool
