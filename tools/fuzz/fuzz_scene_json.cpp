// Fuzz target: scene.json (load_scene_json): lamps, environment, virtual objects, real
// materials. glTF paths it names are resolved, not loaded.
#include <cmath>

#include "fuzz_input.h"
#include "mrgi/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mrgi::fuzz::InputFolder::get().write("scene.json", data, size);
  auto scene = mrgi::load_scene_json(path);
  (void)scene;
  return 0;
}
