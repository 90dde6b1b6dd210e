// Fuzz target: glTF 2.0 through mrgi's loader (load_gltf: tinygltf's parse inside mrgi's bounds,
// accessors, node instancing, textures decoded by libpng / libjpeg-turbo). Binary .glb when the
// input starts with its magic, else .gltf text.
#include <cmath>

#include "fuzz_input.h"
#include "mrgi/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool glb = mrgi::fuzz::starts_with(data, size, "glTF");
  const std::string path = mrgi::fuzz::InputFolder::get().write(glb ? "model.glb" : "model.gltf", data, size);
  auto model = mrgi::load_gltf(path, mrgi::Placement{});
  (void)model;
  return 0;
}
