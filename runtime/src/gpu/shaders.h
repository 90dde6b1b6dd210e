// Embedded SPIR-V by source path relative to shaders/ ("floor.comp", "baseline/shade.comp").
// Built by shaders/CMakeLists.txt with glslangValidator; a GLSL error fails the build.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi::gpu {

// NotFound error listing the embedded shaders when `name` is not one of them.
Expected<std::span<const uint32_t>> shader_spirv(std::string_view name);
std::vector<std::string> shader_names();

}  // namespace mrgi::gpu
