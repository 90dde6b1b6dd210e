// Shader passes of the frame graph: resources bound by the names the shaders declare, each bind
// also the pass's declared use (frame_graph.h, ShaderPassBuilder).
#include <string>

#include "gpu/frame_graph.h"
#include "gpu/frame_graph_entries.h"

namespace mrgi::gpu {
namespace {

// The graph access a declaration implies.
bool access_for(const ShaderBinding& b, Access& out) {
  switch (b.type) {
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
      out = b.read && b.written ? Access::StorageReadWrite : b.written ? Access::StorageWrite : Access::StorageRead;
      return true;
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: out = Access::Sampled; return true;
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER: out = Access::UniformRead; return true;
    default: return false;
  }
}

bool is_image_binding(VkDescriptorType t) {
  return t == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE || t == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
}

}  // namespace

void ShaderPassBuilder::bind(std::string_view name, ImageHandle image) {
  bind_resource(name, ResourceRef{true, image.id}, 0, false, VK_NULL_HANDLE);
}
void ShaderPassBuilder::bind(std::string_view name, ImageHandle image, uint32_t mip) {
  bind_resource(name, ResourceRef{true, image.id}, mip, true, VK_NULL_HANDLE);
}
void ShaderPassBuilder::bind_sampled(std::string_view name, ImageHandle image, VkSampler sampler) {
  bind_resource(name, ResourceRef{true, image.id}, 0, false, sampler);
}
void ShaderPassBuilder::bind(std::string_view name, BufferHandle buffer) {
  bind_resource(name, ResourceRef{false, uint32_t(graph_.images_.size()) + buffer.id}, 0, false, VK_NULL_HANDLE);
}

void ShaderPassBuilder::bind_over(std::string_view name, ImageHandle image) {
  bind_resource(name, ResourceRef{true, image.id}, 0, false, VK_NULL_HANDLE, true);
}
void ShaderPassBuilder::bind_over(std::string_view name, BufferHandle buffer) {
  bind_resource(name, ResourceRef{false, uint32_t(graph_.images_.size()) + buffer.id}, 0, false, VK_NULL_HANDLE, true);
}

void ShaderPassBuilder::bind_resource(std::string_view name, ResourceRef ref, uint32_t mip, bool one_level,
                                      VkSampler sampler, bool over) {
  std::string& error = graph_.setup_error_;
  if (!error.empty()) return;  // the first error is the one reported
  const std::string where = "pass '" + base_.decl_.name + "', binding '" + std::string(name) + "'";
  const ShaderBinding* b = pipeline_.interface.find(name);
  if (!b) {
    std::string names;
    for (const ShaderBinding& x : pipeline_.interface.bindings) names += (names.empty() ? "" : ", ") + x.name;
    error = where + ": not declared by the pass's shaders (they declare: " + names + ")";
    return;
  }
  if (ref.is_image != is_image_binding(b->type)) {
    error = where + ": the shader declares a " + descriptor_type_name(b->type) + ", the pass binds " +
            (ref.is_image ? "an image" : "a buffer");
    return;
  }
  if (b->type == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER && !ref.is_image &&
      graph_.buffers_[ref.id - graph_.images_.size()].copies[0].texel_view == VK_NULL_HANDLE) {
    error = where + ": a storage texel buffer needs a buffer made with BufferDesc::texel_format";
    return;
  }
  if ((b->type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER) != (sampler != VK_NULL_HANDLE)) {
    error = where + (sampler ? ": a sampler given for a " + std::string(descriptor_type_name(b->type))
                             : std::string(": a sampled image needs a sampler (bind_sampled)"));
    return;
  }
  if (b->count != 1) {
    error = where + ": descriptor arrays are bound by hand (plain add_pass)";
    return;
  }
  Access access;
  if (!access_for(*b, access)) {
    error = where + ": a " + std::string(descriptor_type_name(b->type)) + " is not bound by name";
    return;
  }
  if (over) {
    if (access != Access::StorageWrite && access != Access::StorageReadWrite) {
      error = where + ": bind_over is for storage images and buffers the shader writes";
      return;
    }
    access = Access::StorageReadWrite;
  }
  FrameGraph::ShaderPassData& data = graph_.shader_passes_[pass_];
  for (const FrameGraph::BoundDescriptor& d : data.descriptors)
    if (d.binding == b->binding) {
      error = where + ": bound twice";
      return;
    }
  data.descriptors.push_back({b->binding, b->type, ref, mip, one_level, sampler});
  const ResourceUse use = ref.is_image && one_level ? ResourceUse{ref, access, mip, 1} : ResourceUse{ref, access};
  // One resource bound to two names the same way (a stand-in image) is one use of the pass.
  for (const ResourceUse& u : base_.decl_.uses)
    if (u == use) return;
  base_.decl_.uses.push_back(use);
}

void FrameGraph::add_shader_pass(const std::string& name, PassKind kind, const Pipeline& pipeline,
                                 const ShaderSetupFn& setup, ExecuteFn execute) {
  const uint32_t index = pass_count_;
  add_pass(name, kind, [](PassBuilder&) {}, std::move(execute));
  PassBuilder base(*this, decls_[index]);
  ShaderPassData& data = shader_passes_[index];
  data.pipeline = &pipeline;
  data.descriptors.clear();
  ShaderPassBuilder builder(*this, base, pipeline, index);
  setup(builder);
  if (!setup_error_.empty()) return;
  for (const ShaderBinding& b : pipeline.interface.bindings) {
    bool bound = false;
    for (const BoundDescriptor& d : data.descriptors) bound |= d.binding == b.binding;
    if (!bound) {
      setup_error_ = "pass '" + name + "': the shader's " + descriptor_type_name(b.type) + " '" + b.name +
                     "' (binding " + std::to_string(b.binding) + ") is not bound";
      return;
    }
  }
}

void FrameGraph::bind_and_push(VkCommandBuffer cmd, const ShaderPassData& data) const {
  vkCmdBindPipeline(cmd, data.pipeline->bind_point, data.pipeline->pipeline);
  DescriptorPush push;
  for (const BoundDescriptor& d : data.descriptors) {
    if (d.resource.is_image) {
      const GpuImage& img = images_[d.resource.id].gpu;
      const VkImageView view = d.one_level && img.mip_levels > 1 ? img.mip_views[d.mip] : img.view;
      if (d.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE) {
        push.storage_image(d.binding, view);
      } else {
        push.sampled_image(d.binding, view, d.sampler);
      }
    } else {
      const GpuBuffer& buf = gpu_buffer(BufferHandle{d.resource.id - uint32_t(images_.size())}, slot_);
      if (d.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
        push.uniform_buffer(d.binding, buf.buffer);
      } else if (d.type == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER) {
        push.storage_texel_buffer(d.binding, buf.texel_view);
      } else {
        push.storage_buffer(d.binding, buf.buffer);
      }
    }
  }
  push.push(context_, cmd, *data.pipeline);
}

void FrameGraph::run_pass(VkCommandBuffer cmd, uint32_t pass_index, PassContext& ctx) {
  const ShaderPassData& data = shader_passes_[pass_index];
  if (data.pipeline) bind_and_push(cmd, data);
  if (executes_[pass_index]) executes_[pass_index](cmd, ctx);
}

}  // namespace mrgi::gpu
