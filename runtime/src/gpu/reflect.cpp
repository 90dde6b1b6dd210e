#include "gpu/reflect.h"

#include <spirv_cross_c.h>

#include <algorithm>
#include <memory>

namespace mrgi::gpu {
namespace {

struct ContextDeleter {
  void operator()(spvc_context_s* c) const { spvc_context_destroy(c); }
};

Expected<ShaderInterface> reflect_error(const std::string& what, const std::string& why) {
  return fail(ErrorKind::BadUsage, what + ": " + why);
}

// Resource r's descriptor type (listed as `kind`, of type `type`) into b, and for storage
// buffers and images whether the shader reads and writes it.
Status set_descriptor_type(spvc_compiler comp, const spvc_reflected_resource& r, spvc_resource_type kind,
                           spvc_type type, const std::string& what, const std::string& where, ShaderBinding& b) {
  const bool no_write = spvc_compiler_has_decoration(comp, r.id, SpvDecorationNonWritable);
  const bool no_read = spvc_compiler_has_decoration(comp, r.id, SpvDecorationNonReadable);
  switch (kind) {
    case SPVC_RESOURCE_TYPE_UNIFORM_BUFFER:
      b.type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
      break;
    case SPVC_RESOURCE_TYPE_STORAGE_BUFFER: {
      b.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      // readonly / writeonly on a buffer block decorate its members.
      spvc_type block = spvc_compiler_get_type_handle(comp, r.base_type_id);
      const unsigned members = spvc_type_get_num_member_types(block);
      bool all_nonwritable = members > 0, all_nonreadable = members > 0;
      for (unsigned m = 0; m < members; ++m) {
        all_nonwritable &= bool(spvc_compiler_has_member_decoration(comp, r.base_type_id, m, SpvDecorationNonWritable));
        all_nonreadable &= bool(spvc_compiler_has_member_decoration(comp, r.base_type_id, m, SpvDecorationNonReadable));
      }
      b.written = !(all_nonwritable || no_write);
      b.read = !(all_nonreadable || no_read);
      break;
    }
    case SPVC_RESOURCE_TYPE_STORAGE_IMAGE:
      b.type = spvc_type_get_image_dimension(type) == SpvDimBuffer ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER
                                                                  : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
      b.written = !no_write;
      b.read = !no_read;
      break;
    case SPVC_RESOURCE_TYPE_SAMPLED_IMAGE:
      b.type = spvc_type_get_image_dimension(type) == SpvDimBuffer ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                                                  : VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
      break;
    case SPVC_RESOURCE_TYPE_SEPARATE_IMAGE:
      b.type = spvc_type_get_image_dimension(type) == SpvDimBuffer ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                                                  : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
      break;
    case SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS:
      b.type = VK_DESCRIPTOR_TYPE_SAMPLER;
      break;
    default:
      return reflect_error(what, where + ": mrgi does not bind this kind of resource").error();
  }
  return ok_status();
}

}  // namespace

const ShaderBinding* ShaderInterface::find(std::string_view name) const {
  for (const ShaderBinding& b : bindings)
    if (b.name == name) return &b;
  return nullptr;
}

const ShaderBinding* ShaderInterface::at_binding(uint32_t binding) const {
  for (const ShaderBinding& b : bindings)
    if (b.binding == binding) return &b;
  return nullptr;
}

const char* descriptor_type_name(VkDescriptorType type) {
  switch (type) {
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE: return "storage image";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: return "sampled image";
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE: return "separate image";
    case VK_DESCRIPTOR_TYPE_SAMPLER: return "sampler";
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER: return "uniform buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER: return "storage buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER: return "storage texel buffer";
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER: return "uniform texel buffer";
    default: return "other descriptor";
  }
}

Expected<ShaderInterface> reflect_shader(std::span<const uint32_t> spirv, const std::string& what) {
  spvc_context raw = nullptr;
  if (spvc_context_create(&raw) != SPVC_SUCCESS) return reflect_error(what, "SPIRV-Cross could not start");
  std::unique_ptr<spvc_context_s, ContextDeleter> owner(raw);
  spvc_parsed_ir ir = nullptr;
  if (spvc_context_parse_spirv(raw, spirv.data(), spirv.size(), &ir) != SPVC_SUCCESS)
    return reflect_error(what, std::string("SPIR-V not readable: ") + spvc_context_get_last_error_string(raw));
  spvc_compiler comp = nullptr;
  if (spvc_context_create_compiler(raw, SPVC_BACKEND_NONE, ir, SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &comp) != SPVC_SUCCESS)
    return reflect_error(what, std::string("SPIR-V not reflectable: ") + spvc_context_get_last_error_string(raw));
  spvc_resources res = nullptr;
  if (spvc_compiler_create_shader_resources(comp, &res) != SPVC_SUCCESS)
    return reflect_error(what, std::string("no resources: ") + spvc_context_get_last_error_string(raw));

  ShaderInterface out;
  struct Kind {
    spvc_resource_type type;
    const char* name;
  };
  const Kind kinds[] = {
      {SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, "uniform buffer"}, {SPVC_RESOURCE_TYPE_STORAGE_BUFFER, "storage buffer"},
      {SPVC_RESOURCE_TYPE_STORAGE_IMAGE, "storage image"},   {SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, "sampled image"},
      {SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, "separate image"}, {SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, "sampler"},
      {SPVC_RESOURCE_TYPE_SUBPASS_INPUT, "subpass input"},   {SPVC_RESOURCE_TYPE_ACCELERATION_STRUCTURE, "acceleration structure"},
  };
  for (const Kind& k : kinds) {
    const spvc_reflected_resource* list = nullptr;
    size_t n = 0;
    if (spvc_resources_get_resource_list_for_type(res, k.type, &list, &n) != SPVC_SUCCESS) continue;
    for (size_t i = 0; i < n; ++i) {
      const spvc_reflected_resource& r = list[i];
      ShaderBinding b;
      b.name = r.name ? r.name : "";
      const std::string where = std::string(k.name) + " '" + b.name + "'";
      const unsigned set = spvc_compiler_get_decoration(comp, r.id, SpvDecorationDescriptorSet);
      if (set != 0) return reflect_error(what, where + " is in descriptor set " + std::to_string(set) + "; mrgi pushes set 0 only");
      b.binding = spvc_compiler_get_decoration(comp, r.id, SpvDecorationBinding);
      spvc_type type = spvc_compiler_get_type_handle(comp, r.type_id);
      const unsigned dims = spvc_type_get_num_array_dimensions(type);
      if (dims > 1) return reflect_error(what, where + ": arrays of arrays are not bound");
      if (dims == 1) {
        b.count = spvc_type_get_array_dimension(type, 0);
        if (b.count == 0) return reflect_error(what, where + ": runtime-sized descriptor arrays are not bound");
      }
      MRGI_TRY(set_descriptor_type(comp, r, k.type, type, what, where, b));
      if (const ShaderBinding* other = out.at_binding(b.binding))
        return reflect_error(what, where + " and '" + other->name + "' share binding " + std::to_string(b.binding));
      out.bindings.push_back(std::move(b));
    }
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const ShaderBinding& a, const ShaderBinding& b) { return a.binding < b.binding; });
  const spvc_reflected_resource* push = nullptr;
  size_t n_push = 0;
  if (spvc_resources_get_resource_list_for_type(res, SPVC_RESOURCE_TYPE_PUSH_CONSTANT, &push, &n_push) == SPVC_SUCCESS &&
      n_push > 0) {
    size_t size = 0;
    spvc_type block = spvc_compiler_get_type_handle(comp, push[0].base_type_id);
    if (spvc_compiler_get_declared_struct_size(comp, block, &size) != SPVC_SUCCESS)
      return reflect_error(what, "the push-constant block's size is not readable");
    out.push_constant_bytes = uint32_t(size);
  }
  return out;
}

Expected<ShaderInterface> merge_interfaces(const ShaderInterface& a, const ShaderInterface& b, const std::string& what) {
  ShaderInterface out = a;
  for (const ShaderBinding& x : b.bindings) {
    ShaderBinding* same = nullptr;
    for (ShaderBinding& y : out.bindings)
      if (y.binding == x.binding) same = &y;
    if (!same) {
      out.bindings.push_back(x);
      continue;
    }
    if (same->type != x.type || same->count != x.count)
      return fail(ErrorKind::BadUsage, what + ": binding " + std::to_string(x.binding) + " is a " +
                                           descriptor_type_name(same->type) + " '" + same->name + "' in one stage and a " +
                                           descriptor_type_name(x.type) + " '" + x.name + "' in the other");
    same->read |= x.read;
    same->written |= x.written;
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const ShaderBinding& l, const ShaderBinding& r) { return l.binding < r.binding; });
  out.push_constant_bytes = std::max(a.push_constant_bytes, b.push_constant_bytes);
  return out;
}

}  // namespace mrgi::gpu
