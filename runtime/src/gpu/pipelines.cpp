#include "gpu/pipelines.h"

#include "gpu/shaders.h"
#include "gpu/vk_check.h"

namespace mrgi::gpu {
namespace {

Expected<VkShaderModule> make_module(const Context& ctx, std::span<const uint32_t> spirv, const std::string& what) {
  if (spirv.empty() || spirv[0] != 0x07230203u)
    return fail(ErrorKind::BadUsage, what + ": not SPIR-V (empty or wrong magic number)");
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = spirv.size_bytes();
  ci.pCode = spirv.data();
  VkShaderModule m = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(ctx.device(), &ci, nullptr, &m));
  return m;
}

// The descriptor layout: the shader's own declarations (reflect.h). A hand-written list (index =
// binding number), where a caller still gives one, must say the same, binding for binding: a
// binding written in two places that disagree fails here, at start-up, naming both.
Expected<ShaderInterface> resolve_interface(const std::string& name, const ShaderInterface& reflected,
                                            const std::vector<DescriptorBinding>& hand, uint32_t& push_bytes) {
  const std::string what = "pipeline '" + name + "'";
  if (!hand.empty()) {
    for (uint32_t i = 0; i < hand.size(); ++i) {
      const ShaderBinding* b = reflected.at_binding(i);
      if (!b)
        return fail(ErrorKind::BadUsage, what + ": binding " + std::to_string(i) + " (" +
                                             descriptor_type_name(hand[i].type) + ") is not declared by the shader");
      if (b->type != hand[i].type || b->count != hand[i].count)
        return fail(ErrorKind::BadUsage, what + ": binding " + std::to_string(i) + " is a " + descriptor_type_name(hand[i].type) +
                                             " x" + std::to_string(hand[i].count) + " here and a " +
                                             descriptor_type_name(b->type) + " '" + b->name + "' x" +
                                             std::to_string(b->count) + " in the shader");
    }
    for (const ShaderBinding& b : reflected.bindings)
      if (b.binding >= hand.size())
        return fail(ErrorKind::BadUsage, what + ": the shader's " + descriptor_type_name(b.type) + " '" + b.name +
                                             "' (binding " + std::to_string(b.binding) + ") is missing here");
  }
  // Push constants: the C++ block is at least the GLSL one (it may round up to 16 bytes).
  const uint32_t declared = (reflected.push_constant_bytes + 3u) & ~3u;
  if (push_bytes == 0) push_bytes = declared;
  if (push_bytes < declared)
    return fail(ErrorKind::BadUsage, what + ": " + std::to_string(push_bytes) + " bytes of push constants, the shader declares " +
                                         std::to_string(reflected.push_constant_bytes));
  return reflected;
}

// Set 0 as a push-descriptor set, and the pipeline layout around it.
Status make_layouts(const Context& ctx, const std::string& name, const ShaderInterface& iface,
                    VkShaderStageFlags stages, uint32_t push_bytes, Pipeline& p) {
  if (push_bytes > ctx.properties().limits.maxPushConstantsSize)
    return fail(ErrorKind::BadUsage, "pipeline '" + name + "': " + std::to_string(push_bytes) +
                                         " bytes of push constants exceed the device limit " +
                                         std::to_string(ctx.properties().limits.maxPushConstantsSize));
  if (push_bytes % 4 != 0)
    return fail(ErrorKind::BadUsage, "pipeline '" + name + "': push constant size must be a multiple of 4");
  // Every binding is pushed each time the pipeline is used (DescriptorPush): no more than it holds.
  if (iface.bindings.size() > DescriptorPush::kMaxWrites)
    return fail(ErrorKind::BadUsage, "pipeline '" + name + "': " + std::to_string(iface.bindings.size()) +
                                         " descriptor bindings, more than a push-descriptor set takes (" +
                                         std::to_string(DescriptorPush::kMaxWrites) + ")");
  std::vector<VkDescriptorSetLayoutBinding> b(iface.bindings.size());
  for (size_t i = 0; i < iface.bindings.size(); ++i) {
    b[i].binding = iface.bindings[i].binding;
    b[i].descriptorType = iface.bindings[i].type;
    b[i].descriptorCount = iface.bindings[i].count;
    b[i].stageFlags = stages;
  }
  VkDescriptorSetLayoutCreateInfo dci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dci.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  dci.bindingCount = uint32_t(b.size());
  dci.pBindings = b.data();
  VK_CHECK(vkCreateDescriptorSetLayout(ctx.device(), &dci, nullptr, &p.set_layout));
  VkPushConstantRange range{stages, 0, push_bytes};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = 1;
  lci.pSetLayouts = &p.set_layout;
  lci.pushConstantRangeCount = push_bytes > 0 ? 1 : 0;
  lci.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(ctx.device(), &lci, nullptr, &p.layout));
  p.stages = stages;
  p.push_constant_bytes = push_bytes;
  p.interface = iface;
  return ok_status();
}

// The graphics pipelines' fixed-function states that depend on the description.
VkPipelineRasterizationStateCreateInfo rasterization_state(const GraphicsPipelineDesc& desc) {
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = desc.cull_mode;
  rs.frontFace = desc.front_face;
  rs.lineWidth = 1.0f;
  rs.depthBiasEnable = (desc.depth_bias_constant != 0.0f || desc.depth_bias_slope != 0.0f) ? VK_TRUE : VK_FALSE;
  rs.depthBiasConstantFactor = desc.depth_bias_constant;
  rs.depthBiasSlopeFactor = desc.depth_bias_slope;
  return rs;
}

VkPipelineDepthStencilStateCreateInfo depth_stencil_state(const GraphicsPipelineDesc& desc) {
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  const bool has_depth = desc.depth_format != VK_FORMAT_UNDEFINED;
  ds.depthTestEnable = has_depth && desc.depth_test;
  ds.depthWriteEnable = has_depth && desc.depth_write;
  ds.depthCompareOp = desc.depth_compare;
  return ds;
}

std::vector<VkPipelineColorBlendAttachmentState> blend_attachments(const GraphicsPipelineDesc& desc) {
  std::vector<VkPipelineColorBlendAttachmentState> blend(desc.color_formats.size());
  for (auto& b : blend) {
    b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                       VK_COLOR_COMPONENT_A_BIT;
    if (desc.additive_blend) {
      b.blendEnable = VK_TRUE;
      b.srcColorBlendFactor = b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
      b.srcAlphaBlendFactor = b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      b.colorBlendOp = b.alphaBlendOp = VK_BLEND_OP_ADD;
    }
  }
  return blend;
}

// The vertex and fragment shaders' interface, merged and resolved against desc.bindings
// (push_bytes: in, the description's push-constant size; out, the resolved one).
Expected<ShaderInterface> graphics_interface(const GraphicsPipelineDesc& desc, const std::string& what,
                                             uint32_t& push_bytes) {
  Expected<ShaderInterface> iface = reflect_shader(desc.vertex_spirv, what + " vertex shader");
  if (iface && !desc.fragment_spirv.empty()) {
    auto f = reflect_shader(desc.fragment_spirv, what + " fragment shader");
    iface = f ? merge_interfaces(*iface, *f, what) : Expected<ShaderInterface>(f.error());
  }
  if (iface) iface = resolve_interface(desc.name, *iface, desc.bindings, push_bytes);
  return iface;
}

// The pipeline object of `desc` with the shader modules vs and fs (none: VK_NULL_HANDLE) and
// p's layout, into p.pipeline.
Status create_graphics_vk_pipeline(const Context& ctx, const GraphicsPipelineDesc& desc, VkShaderModule vs,
                                   VkShaderModule fs, Pipeline& p) {
  VkPipelineShaderStageCreateInfo st[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                           {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  st[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  st[0].module = vs;
  st[0].pName = "main";
  st[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  st[1].module = fs;
  st[1].pName = "main";
  std::vector<VkVertexInputBindingDescription> vb;
  for (uint32_t i = 0; i < desc.vertex_strides.size(); ++i)
    vb.push_back({i, desc.vertex_strides[i], VK_VERTEX_INPUT_RATE_VERTEX});
  std::vector<VkVertexInputAttributeDescription> va;
  for (const VertexAttribute& a : desc.attributes) va.push_back({a.location, a.binding, a.format, a.offset});
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = uint32_t(vb.size());
  vi.pVertexBindingDescriptions = vb.data();
  vi.vertexAttributeDescriptionCount = uint32_t(va.size());
  vi.pVertexAttributeDescriptions = va.data();
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = desc.topology;
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  const VkPipelineRasterizationStateCreateInfo rs = rasterization_state(desc);
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  const VkPipelineDepthStencilStateCreateInfo ds = depth_stencil_state(desc);
  const std::vector<VkPipelineColorBlendAttachmentState> blend = blend_attachments(desc);
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = uint32_t(blend.size());
  cb.pAttachments = blend.data();
  const VkDynamicState dyn[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dyn;
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = uint32_t(desc.color_formats.size());
  ri.pColorAttachmentFormats = desc.color_formats.data();
  ri.depthAttachmentFormat = desc.depth_format;
  VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  ci.pNext = &ri;
  ci.stageCount = fs ? 2 : 1;
  ci.pStages = st;
  ci.pVertexInputState = &vi;
  ci.pInputAssemblyState = &ia;
  ci.pViewportState = &vp;
  ci.pRasterizationState = &rs;
  ci.pMultisampleState = &ms;
  ci.pDepthStencilState = &ds;
  ci.pColorBlendState = &cb;
  ci.pDynamicState = &dy;
  ci.layout = p.layout;
  return VK_STATUS(vkCreateGraphicsPipelines(ctx.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline));
}

}  // namespace

Expected<Pipeline> create_compute_pipeline(const Context& ctx, const ComputePipelineDesc& desc) {
  Pipeline p;
  p.bind_point = VK_PIPELINE_BIND_POINT_COMPUTE;
  auto reflected = reflect_shader(desc.spirv, "compute pipeline '" + desc.name + "'");
  if (!reflected) return reflected.error();
  uint32_t push_bytes = desc.push_constant_bytes;
  auto iface = resolve_interface(desc.name, *reflected, desc.bindings, push_bytes);
  if (!iface) return iface.error();
  auto module = make_module(ctx, desc.spirv, "compute pipeline '" + desc.name + "'");
  if (!module) return module.error();
  Status s = make_layouts(ctx, desc.name, *iface, VK_SHADER_STAGE_COMPUTE_BIT, push_bytes, p);
  if (s.ok()) {
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = *module;
    ci.stage.pName = "main";
    std::vector<VkSpecializationMapEntry> entries(desc.specialization.size());
    for (uint32_t i = 0; i < entries.size(); ++i) entries[i] = {i, i * 4u, 4u};
    VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), desc.specialization.size() * 4,
                              desc.specialization.data()};
    if (!entries.empty()) ci.stage.pSpecializationInfo = &spec;
    ci.layout = p.layout;
    s = VK_STATUS(vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline));
  }
  vkDestroyShaderModule(ctx.device(), *module, nullptr);
  if (!s) {
    destroy_pipeline(ctx, p);
    return fail(s.error().kind, "compute pipeline '" + desc.name + "': " + s.error().message);
  }
  ctx.set_name(VK_OBJECT_TYPE_PIPELINE, uint64_t(p.pipeline), desc.name);
  return p;
}

Expected<Pipeline> create_graphics_pipeline(const Context& ctx, const GraphicsPipelineDesc& desc) {
  Pipeline p;
  p.bind_point = VK_PIPELINE_BIND_POINT_GRAPHICS;
  const std::string what = "graphics pipeline '" + desc.name + "'";
  if (desc.color_formats.empty() && desc.depth_format == VK_FORMAT_UNDEFINED)
    return fail(ErrorKind::BadUsage, what + ": no colour or depth attachment");
  for (const VertexAttribute& a : desc.attributes)
    if (a.binding >= desc.vertex_strides.size())
      return fail(ErrorKind::BadUsage, what + ": attribute at location " + std::to_string(a.location) +
                                           " names vertex binding " + std::to_string(a.binding) + ", which has no stride");
  auto vs = make_module(ctx, desc.vertex_spirv, what + " vertex shader");
  if (!vs) return vs.error();
  VkShaderModule fs = VK_NULL_HANDLE;
  if (!desc.fragment_spirv.empty()) {
    auto m = make_module(ctx, desc.fragment_spirv, what + " fragment shader");
    if (!m) {
      vkDestroyShaderModule(ctx.device(), *vs, nullptr);
      return m.error();
    }
    fs = *m;
  }
  const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  uint32_t push_bytes = desc.push_constant_bytes;
  Expected<ShaderInterface> iface = graphics_interface(desc, what, push_bytes);
  if (!iface) {
    vkDestroyShaderModule(ctx.device(), *vs, nullptr);
    if (fs) vkDestroyShaderModule(ctx.device(), fs, nullptr);
    return iface.error();
  }
  Status s = make_layouts(ctx, desc.name, *iface, stages, push_bytes, p);
  if (s.ok()) s = create_graphics_vk_pipeline(ctx, desc, *vs, fs, p);
  vkDestroyShaderModule(ctx.device(), *vs, nullptr);
  if (fs) vkDestroyShaderModule(ctx.device(), fs, nullptr);
  if (!s) {
    destroy_pipeline(ctx, p);
    return fail(s.error().kind, what + ": " + s.error().message);
  }
  ctx.set_name(VK_OBJECT_TYPE_PIPELINE, uint64_t(p.pipeline), desc.name);
  return p;
}

void destroy_pipeline(const Context& ctx, Pipeline& p) {
  if (p.pipeline) vkDestroyPipeline(ctx.device(), p.pipeline, nullptr);
  if (p.layout) vkDestroyPipelineLayout(ctx.device(), p.layout, nullptr);
  if (p.set_layout) vkDestroyDescriptorSetLayout(ctx.device(), p.set_layout, nullptr);
  p = Pipeline{};
}

PipelineHandle& PipelineHandle::operator=(PipelineHandle&& o) noexcept {
  if (this != &o) {
    reset();
    ctx_ = o.ctx_;
    p_ = std::move(o.p_);
    o.p_ = {};
  }
  return *this;
}

void PipelineHandle::reset() {
  if (ctx_ && p_.pipeline) destroy_pipeline(*ctx_, p_);
  p_ = {};
}

VkWriteDescriptorSet* DescriptorPush::next_write(uint32_t binding, VkDescriptorType type) {
  if (count_ >= kMaxWrites) {
    overflow_ = true;
    return nullptr;
  }
  VkWriteDescriptorSet& w = writes_[count_];
  w = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = type;
  return &w;
}

DescriptorPush& DescriptorPush::storage_image(uint32_t binding, VkImageView view) {
  if (VkWriteDescriptorSet* w = next_write(binding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE)) {
    images_[count_] = {VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    w->pImageInfo = &images_[count_++];
  }
  return *this;
}

DescriptorPush& DescriptorPush::sampled_image(uint32_t binding, VkImageView view, VkSampler sampler) {
  if (VkWriteDescriptorSet* w = next_write(binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER)) {
    images_[count_] = {sampler, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    w->pImageInfo = &images_[count_++];
  }
  return *this;
}

DescriptorPush& DescriptorPush::storage_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset,
                                               VkDeviceSize range) {
  if (VkWriteDescriptorSet* w = next_write(binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)) {
    buffers_[count_] = {buffer, offset, range};
    w->pBufferInfo = &buffers_[count_++];
  }
  return *this;
}

DescriptorPush& DescriptorPush::storage_texel_buffer(uint32_t binding, VkBufferView view) {
  if (VkWriteDescriptorSet* w = next_write(binding, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER)) {
    texel_views_[count_] = view;
    w->pTexelBufferView = &texel_views_[count_++];
  }
  return *this;
}

DescriptorPush& DescriptorPush::uniform_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset,
                                               VkDeviceSize range) {
  storage_buffer(binding, buffer, offset, range);
  if (!overflow_) writes_[count_ - 1].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  return *this;
}

void DescriptorPush::push(const Context& ctx, VkCommandBuffer cmd, const Pipeline& pipeline) {
  // More than kMaxWrites is a programming error in a pass; pushing a truncated set would make the
  // validation layer (and the tests) report the unbound descriptors, so push what fits.
  if (count_ == 0) return;
  ctx.cmd_push_descriptor_set()(cmd, pipeline.bind_point, pipeline.layout, 0, count_, writes_.data());
}

void dispatch_2d(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants, uint32_t bytes,
                 uint32_t width, uint32_t height, uint32_t local_x, uint32_t local_y) {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
  if (bytes > 0 && push_constants)
    vkCmdPushConstants(cmd, pipeline.layout, pipeline.stages, 0, bytes, push_constants);
  vkCmdDispatch(cmd, (width + local_x - 1) / local_x, (height + local_y - 1) / local_y, 1);
}

void push_and_dispatch(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants, uint32_t bytes,
                       VkExtent3D groups) {
  if (bytes > 0 && push_constants)
    vkCmdPushConstants(cmd, pipeline.layout, pipeline.stages, 0, bytes, push_constants);
  vkCmdDispatch(cmd, groups.width, groups.height, groups.depth);
}

void dispatch_indirect(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants,
                       uint32_t bytes, VkBuffer args, VkDeviceSize offset) {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
  if (bytes > 0 && push_constants)
    vkCmdPushConstants(cmd, pipeline.layout, pipeline.stages, 0, bytes, push_constants);
  vkCmdDispatchIndirect(cmd, args, offset);
}

void reset_dispatch_args(VkCommandBuffer cmd, VkBuffer args, bool zero_rest) {
  // Three fills over disjoint ranges: overlapping ones in one pass are a write-after-write hazard.
  vkCmdFillBuffer(cmd, args, 0, 4, 0u);  // x groups
  vkCmdFillBuffer(cmd, args, 4, 8, 1u);  // y, z
  if (zero_rest) vkCmdFillBuffer(cmd, args, 12, VK_WHOLE_SIZE, 0u);
}

Status require_bindings(const Pipeline& pipeline, const std::string& what,
                        std::initializer_list<std::string_view> names) {
  for (std::string_view n : names)
    if (!pipeline.interface.find(n))
      return fail(ErrorKind::BadUsage, "pipeline '" + what + "': its shaders declare no binding '" + std::string(n) + "'");
  return ok_status();
}

Expected<PipelineHandle> load_compute_pipeline(const Context& ctx, const char* shader,
                                               std::vector<DescriptorBinding> bindings,
                                               uint32_t push_constant_bytes) {
  auto spirv = shader_spirv(shader);
  if (!spirv) return spirv.error();
  ComputePipelineDesc d;
  d.name = shader;
  d.spirv = *spirv;
  d.bindings = std::move(bindings);
  d.push_constant_bytes = push_constant_bytes;
  auto p = create_compute_pipeline(ctx, d);
  if (!p) return p.error();
  return PipelineHandle(ctx, std::move(*p));
}

}  // namespace mrgi::gpu
