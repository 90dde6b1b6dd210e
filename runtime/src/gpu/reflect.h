// What a shader declares, read from its SPIR-V (SPIRV-Cross's reflection): every descriptor of
// set 0 with its GLSL name, binding, type, array size and whether the shader only reads or only
// writes it, and the size of its push-constant block. The GLSL declaration is then the one place
// a binding is written: pipelines take their descriptor layout from it, and a pass binds its
// resources by the GLSL name, the frame graph deriving the access from the descriptor type and the
// readonly / writeonly qualifiers.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi::gpu {

struct ShaderBinding {
  std::string name;          // the variable's GLSL name (a block without one: its type's name)
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  uint32_t count = 1;        // array size
  bool read = true;          // storage images and buffers: not writeonly
  bool written = false;      // storage images and buffers: not readonly
  bool operator==(const ShaderBinding&) const = default;
};

struct ShaderInterface {
  std::vector<ShaderBinding> bindings;  // by binding number, ascending
  uint32_t push_constant_bytes = 0;     // the push-constant block's declared size (0: none)
  const ShaderBinding* find(std::string_view name) const;
  const ShaderBinding* at_binding(uint32_t binding) const;
};

// BadUsage naming `what` for SPIR-V SPIRV-Cross cannot parse, a descriptor outside set 0 (mrgi
// pushes set 0 only), a runtime-sized array or a resource kind mrgi does not bind.
Expected<ShaderInterface> reflect_shader(std::span<const uint32_t> spirv, const std::string& what);

// The union of two stages' interfaces (vertex + fragment). BadUsage where one binding number
// has two different declarations.
Expected<ShaderInterface> merge_interfaces(const ShaderInterface& a, const ShaderInterface& b, const std::string& what);

const char* descriptor_type_name(VkDescriptorType type);

}  // namespace mrgi::gpu
