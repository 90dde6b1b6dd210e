// Fuzz target: mrgi's own structure check of OpenNI .oni recordings (oni_file_inspector.h), the
// gate in front of OpenNI2's file driver.
#include "fuzz_input.h"
#include "openni/oni_file_inspector.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mrgi::fuzz::InputFolder::get().write("recording.oni", data, size);
  auto summary = mrgi::oni::inspect_oni_file(path);
  (void)summary;
  return 0;
}
