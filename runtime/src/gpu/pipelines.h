// Pipelines from embedded SPIR-V. Descriptors are push descriptors (VK_KHR_push_descriptor):
// set 0 of every pipeline is a push-descriptor set, so nothing is allocated per frame and no
// pool is needed. Push constants are visible to all the pipeline's stages.
#pragma once
#include <initializer_list>
#include <string_view>
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/reflect.h"
#include "mrgi/expected.h"

namespace mrgi::gpu {

// Binding i of set 0 (index in the vector = binding number). Optional: a pipeline's layout comes
// from its shaders' declarations (reflect.h); a list given here is checked against them.
struct DescriptorBinding {
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  uint32_t count = 1;
};

struct ComputePipelineDesc {
  std::string name;                    // for errors and debug names
  std::span<const uint32_t> spirv;     // entry point "main"
  std::vector<DescriptorBinding> bindings;  // empty: the shader's (checked when given)
  uint32_t push_constant_bytes = 0;    // <= 128 (the guaranteed minimum); 0: the shader's block
  // Specialization constants: value i sets `layout(constant_id = i)` (32-bit int, uint or bool).
  // A path a configuration never takes should be compiled out this way, not branched around:
  // lavapipe runs every path of a shader at every invocation (compose.comp measured it).
  std::vector<uint32_t> specialization;
};

struct VertexAttribute {
  uint32_t location = 0;
  uint32_t binding = 0;
  VkFormat format = VK_FORMAT_R32G32B32_SFLOAT;
  uint32_t offset = 0;                 // bytes
};

struct GraphicsPipelineDesc {
  std::string name;
  std::span<const uint32_t> vertex_spirv;
  std::span<const uint32_t> fragment_spirv;  // empty: depth-only (shadow maps)
  std::vector<DescriptorBinding> bindings;  // empty: the shaders' (checked when given)
  uint32_t push_constant_bytes = 0;          // 0: the shaders' block
  std::vector<uint32_t> vertex_strides;      // bytes, one per vertex binding (per-vertex rate)
  std::vector<VertexAttribute> attributes;
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  std::vector<VkFormat> color_formats;       // dynamic rendering attachments
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  bool depth_test = true;
  bool depth_write = true;
  VkCompareOp depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL;
  VkCullModeFlags cull_mode = VK_CULL_MODE_BACK_BIT;
  VkFrontFace front_face = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  // Depth bias for shadow maps (0 = off): constant in depth units, slope in units per slope.
  float depth_bias_constant = 0.0f;
  float depth_bias_slope = 0.0f;
  bool additive_blend = false;               // colour = src + dst on every attachment
};

// Viewport and scissor are dynamic state (set per pass from the used extent).
struct Pipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineBindPoint bind_point = VK_PIPELINE_BIND_POINT_COMPUTE;
  VkShaderStageFlags stages = 0;
  uint32_t push_constant_bytes = 0;
  ShaderInterface interface;  // set 0 as the shaders declare it, with the GLSL names
};

Expected<Pipeline> create_compute_pipeline(const Context& ctx, const ComputePipelineDesc& desc);
Expected<Pipeline> create_graphics_pipeline(const Context& ctx, const GraphicsPipelineDesc& desc);
void destroy_pipeline(const Context& ctx, Pipeline& pipeline);

// Owns a pipeline and destroys it with the context's device.
class PipelineHandle {
 public:
  PipelineHandle() = default;
  PipelineHandle(const Context& ctx, Pipeline p) : ctx_(&ctx), p_(std::move(p)) {}
  ~PipelineHandle() { reset(); }
  PipelineHandle(PipelineHandle&& o) noexcept : ctx_(o.ctx_), p_(std::move(o.p_)) { o.p_ = {}; }
  PipelineHandle& operator=(PipelineHandle&& o) noexcept;
  PipelineHandle(const PipelineHandle&) = delete;
  PipelineHandle& operator=(const PipelineHandle&) = delete;
  const Pipeline& operator*() const { return p_; }
  const Pipeline* operator->() const { return &p_; }
  void reset();

 private:
  const Context* ctx_ = nullptr;
  Pipeline p_;
};

// Collects up to 32 descriptor writes on the stack and pushes them (no heap, no pool); 32 is
// VK_KHR_push_descriptor's guaranteed maxPushDescriptors, and make_layouts refuses a pipeline
// with more bindings.
// Images: storage images are in GENERAL, sampled ones in SHADER_READ_ONLY_OPTIMAL (what the frame
// graph transitions them to).
class DescriptorPush {
 public:
  static constexpr uint32_t kMaxWrites = 32;
  DescriptorPush& storage_image(uint32_t binding, VkImageView view);
  DescriptorPush& sampled_image(uint32_t binding, VkImageView view, VkSampler sampler);
  DescriptorPush& storage_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset = 0,
                                 VkDeviceSize range = VK_WHOLE_SIZE);
  DescriptorPush& uniform_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset = 0,
                                 VkDeviceSize range = VK_WHOLE_SIZE);
  DescriptorPush& storage_texel_buffer(uint32_t binding, VkBufferView view);
  // Binds nothing else: call after vkCmdBindPipeline.
  void push(const Context& ctx, VkCommandBuffer cmd, const Pipeline& pipeline);

 private:
  // The next write with its common fields set; nullptr (and overflow_) when all are used.
  VkWriteDescriptorSet* next_write(uint32_t binding, VkDescriptorType type);
  std::array<VkWriteDescriptorSet, kMaxWrites> writes_{};
  std::array<VkDescriptorImageInfo, kMaxWrites> images_{};
  std::array<VkDescriptorBufferInfo, kMaxWrites> buffers_{};
  std::array<VkBufferView, kMaxWrites> texel_views_{};
  uint32_t count_ = 0;
  bool overflow_ = false;
};

// Binds `pipeline`, pushes constants (`bytes` must equal the pipeline's push_constant_bytes)
// and dispatches ceil(width/local_x) x ceil(height/local_y) groups.
void dispatch_2d(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants,
                 uint32_t bytes, uint32_t width, uint32_t height, uint32_t local_x = 8,
                 uint32_t local_y = 8);

// For a pass whose pipeline the frame graph bound (FrameGraph::add_shader_pass): pushes the
// constants (`bytes` = the pipeline's push_constant_bytes, or 0) and dispatches `groups`.
void push_and_dispatch(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants, uint32_t bytes,
                       VkExtent3D groups);

// Binds, pushes the constants and dispatches the workgroup counts a GPU pass wrote into `args`
// at `offset` (a VkDispatchIndirectCommand; the pass declares it Access::IndirectRead).
void dispatch_indirect(VkCommandBuffer cmd, const Pipeline& pipeline, const void* push_constants,
                       uint32_t bytes, VkBuffer args, VkDeviceSize offset = 0);

// Resets a VkDispatchIndirectCommand at the start of `args` to (0, 1, 1) for a pass that counts
// workgroups into x with atomics (a transfer pass; the buffer needs TRANSFER_DST usage), and with
// `zero_rest` every byte after it to 0 too (flags a counting pass keeps beside the arguments).
void reset_dispatch_args(VkCommandBuffer cmd, VkBuffer args, bool zero_rest = false);

// For passes that push descriptors by hand (several pipelines in one pass, where
// FrameGraph::add_shader_pass does not apply): checked once when the pipeline is made, so that
// pipeline.interface.find(name)->binding is safe when recording. BadUsage names `what` (the
// pipeline) and the binding its shaders do not declare.
Status require_bindings(const Pipeline& pipeline, const std::string& what,
                        std::initializer_list<std::string_view> names);

// A compute pipeline from a registered shader (shaders.h: "folder/name.comp"), owned.
Expected<PipelineHandle> load_compute_pipeline(const Context& ctx, const char* shader,
                                               std::vector<DescriptorBinding> bindings,
                                               uint32_t push_constant_bytes = 0);

}  // namespace mrgi::gpu
