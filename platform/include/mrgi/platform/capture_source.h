/// \file
/// Capture replay as an InputSource: frames of a capture folder (format v1) in order, then
/// ErrorKind::EndOfStream. open_source() dispatches plain folder paths here.
#pragma once
#include <memory>
#include <string>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/platform/source.h"

namespace mrgi {

/// Opens FOLDER with CaptureReader::open (all its checks) and replays it. Never waits: next()
/// returns at once whatever the timeout.
MRGI_API Expected<std::unique_ptr<InputSource>> make_capture_source(const std::string& folder);

}  // namespace mrgi
