// Fuzz target: capture.json (load_capture_json), the capture's intrinsics, depth scale and lists.
#include "fuzz_input.h"
#include "mrgi/platform/capture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mrgi::fuzz::InputFolder::get().write("capture.json", data, size);
  auto info = mrgi::load_capture_json(path);
  (void)info;
  return 0;
}
