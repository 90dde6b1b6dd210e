// Fuzz target: the TUM-style lists of a capture (rgb.txt, depth.txt, env.txt; capture_text.h).
#include <cmath>

#include "capture/capture_text.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mrgi::fuzz::InputFolder::get().write("rgb.txt", data, size);
  auto lines = mrgi::capture::read_list(path, 1, 2, "timestamp path");
  if (lines.ok()) {
    // The reader's promises: finite, strictly increasing timestamps; 1-2 fields per line.
    double last = -INFINITY;
    for (const auto& l : *lines) {
      if (!std::isfinite(l.timestamp) || !(l.timestamp > last) || l.fields.empty() || l.fields.size() > 2)
        std::abort();
      last = l.timestamp;
    }
  }
  return 0;
}
