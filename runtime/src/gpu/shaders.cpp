#include "gpu/shaders.h"

#include "mrgi_shader_registry.inc"

namespace mrgi::gpu {

Expected<std::span<const uint32_t>> shader_spirv(std::string_view name) {
  for (const MrgiShaderEntry& e : kMrgiShaderEntries)
    if (name == e.name) return std::span<const uint32_t>(e.words, e.word_count);
  std::string known;
  for (const MrgiShaderEntry& e : kMrgiShaderEntries) known += std::string(known.empty() ? "" : ", ") + e.name;
  return fail(ErrorKind::NotFound, "shader '" + std::string(name) + "' is not embedded (known: " + known +
                                       "); shaders/CMakeLists.txt embeds shaders/*.{comp,vert,frag} and one folder deep");
}

std::vector<std::string> shader_names() {
  std::vector<std::string> names;
  for (const MrgiShaderEntry& e : kMrgiShaderEntries) names.emplace_back(e.name);
  return names;
}

}  // namespace mrgi::gpu
