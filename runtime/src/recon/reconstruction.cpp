#include "recon/reconstruction.h"

#include <cstring>

#include "gpu/shaders.h"

namespace mrgi::recon {
namespace {

// Shader buffers are read as 32-bit words: round byte sizes up to a multiple of 4.
size_t words_bytes(size_t bytes) { return (bytes + 3) / 4 * 4; }

Expected<gpu::ImageHandle> internal_image(gpu::FrameGraph& graph, const char* name, VkFormat format,
                                          VkImageUsageFlags usage) {
  gpu::ImageDesc d;
  d.name = name;
  d.format = format;
  d.size_mode = gpu::SizeMode::OutputRelative;
  d.scale = 1.0f;
  d.follows_render_scale = true;
  return graph.create_image(d, usage);
}

}  // namespace

Expected<Reconstruction> Reconstruction::create(gpu::Context& context, gpu::FrameGraph& graph,
                                                const Intrinsics& color, const Intrinsics& depth) {
  Reconstruction r;
  r.color_bytes_ = size_t(color.width) * color.height * 3;
  r.depth_bytes_ = size_t(depth.width) * depth.height * 2;
  gpu::BufferDesc cb{"color_upload", words_bytes(r.color_bytes_), gpu::MemoryUsage::Upload, true};
  auto c = graph.create_buffer(cb, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!c) return c.error();
  r.color_upload_ = *c;
  gpu::BufferDesc db{"depth_upload", words_bytes(r.depth_bytes_), gpu::MemoryUsage::Upload, true};
  auto d = graph.create_buffer(db, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!d) return d.error();
  r.depth_upload_ = *d;

  const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  auto p = internal_image(graph, "real_position", VK_FORMAT_R32G32B32A32_SFLOAT, usage);
  if (!p) return p.error();
  r.position_ = *p;
  auto n = internal_image(graph, "real_normal", VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  if (!n) return n.error();
  r.normal_ = *n;
  auto a = internal_image(graph, "real_albedo", VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  if (!a) return a.error();
  r.albedo_ = *a;

  const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  const auto img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  auto pos_spv = gpu::shader_spirv("recon/depth_to_positions.comp");
  if (!pos_spv) return pos_spv.error();
  auto pp = gpu::create_compute_pipeline(
      context, {"recon_positions", *pos_spv, {{ubo}, {ssbo}, {ssbo}, {img}, {img}}, 0});
  if (!pp) return pp.error();
  r.positions_pipeline_ = gpu::PipelineHandle(context, std::move(*pp));
  auto nrm_spv = gpu::shader_spirv("recon/normals.comp");
  if (!nrm_spv) return nrm_spv.error();
  auto np = gpu::create_compute_pipeline(context, {"recon_normals", *nrm_spv, {{ubo}, {img}, {img}}, 0});
  if (!np) return np.error();
  r.normals_pipeline_ = gpu::PipelineHandle(context, std::move(*np));
  return r;
}

void Reconstruction::upload(const gpu::FrameGraph& graph, const InputFrame& frame) const {
  std::memcpy(graph.mapped(color_upload_, graph.slot()), frame.color.data.data(), color_bytes_);
  std::memcpy(graph.mapped(depth_upload_, graph.slot()), frame.depth.data.data(), depth_bytes_);
}

void Reconstruction::record(gpu::FrameGraph& graph, gpu::BufferHandle frame_constants) {
  frame_constants_ = frame_constants;
  graph.add_pass(
      "recon_positions", gpu::PassKind::Compute,
      [this](gpu::PassBuilder& b) {
        b.read(frame_constants_, gpu::Access::UniformRead);
        b.read(color_upload_, gpu::Access::StorageRead);
        b.read(depth_upload_, gpu::Access::StorageRead);
        b.write(position_, gpu::Access::StorageWrite);
        b.write(albedo_, gpu::Access::StorageWrite);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, positions_pipeline_->pipeline);
        gpu::DescriptorPush()
            .uniform_buffer(0, pass.buffer(frame_constants_))
            .storage_buffer(1, pass.buffer(color_upload_))
            .storage_buffer(2, pass.buffer(depth_upload_))
            .storage_image(3, pass.view(position_))
            .storage_image(4, pass.view(albedo_))
            .push(pass.context(), cmd, *positions_pipeline_);
        const VkExtent2D e = pass.extent(position_);
        gpu::dispatch_2d(cmd, *positions_pipeline_, nullptr, 0, e.width, e.height);
      });
  graph.add_pass(
      "recon_normals", gpu::PassKind::Compute,
      [this](gpu::PassBuilder& b) {
        b.read(frame_constants_, gpu::Access::UniformRead);
        b.read(position_, gpu::Access::StorageRead);
        b.write(normal_, gpu::Access::StorageWrite);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, normals_pipeline_->pipeline);
        gpu::DescriptorPush()
            .uniform_buffer(0, pass.buffer(frame_constants_))
            .storage_image(1, pass.view(position_))
            .storage_image(2, pass.view(normal_))
            .push(pass.context(), cmd, *normals_pipeline_);
        const VkExtent2D e = pass.extent(normal_);
        gpu::dispatch_2d(cmd, *normals_pipeline_, nullptr, 0, e.width, e.height);
      });
}

}  // namespace mrgi::recon
