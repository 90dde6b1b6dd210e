#include "specular/mesh_raster.h"

namespace mrgi::specular {

void add_mesh_raster(gpu::FrameGraph& graph, const frame::SceneGpu& scene, const MeshRaster& r) {
  const frame::SceneGpu* sg = &scene;
  graph.add_pass(
      r.name, gpu::PassKind::Graphics,
      [sg, r](gpu::PassBuilder& b) {
        b.read(sg->virtual_objects.vertices, gpu::Access::VertexBuffer);
        b.read(sg->virtual_objects.indices, gpu::Access::IndexBuffer);
        b.read(sg->materials, gpu::Access::StorageRead);
        for (gpu::ImageHandle h : r.colour) b.write(h, gpu::Access::ColorAttachmentWrite);
        b.write(r.depth, gpu::Access::DepthAttachmentWrite);
      },
      [sg, r](VkCommandBuffer cmd, gpu::PassContext& p) {
        const gpu::Context& ctx = p.context();
        const VkExtent2D e = r.extent.width > 0 ? r.extent : p.extent(r.colour[0]);
        std::vector<VkRenderingAttachmentInfo> colour(r.colour.size());
        for (size_t i = 0; i < r.colour.size(); ++i) {
          colour[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
          colour[i].imageView = p.view(r.colour[i]);
          colour[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
          colour[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
          colour[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
          colour[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
        }
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = p.view(r.depth);
        depth.imageLayout = gpu::access_info(gpu::PassKind::Graphics, gpu::Access::DepthAttachmentWrite, true, true).layout;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        const VkRect2D area = r.area ? *r.area : VkRect2D{{0, 0}, e};
        ri.renderArea = area;
        ri.layerCount = 1;
        ri.colorAttachmentCount = uint32_t(colour.size());
        ri.pColorAttachments = colour.data();
        ri.pDepthAttachment = &depth;
        ctx.fn().cmd_begin_rendering(cmd, &ri);
        const VkViewport vp{0.0f, 0.0f, float(e.width), float(e.height), 0.0f, 1.0f};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &area);
        const gpu::Pipeline* pipe = r.pipeline;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe->pipeline);
        gpu::DescriptorPush().storage_buffer(pipe->interface.find("Materials")->binding, p.buffer(sg->materials)).push(ctx, cmd, *pipe);
        VkBuffer vb = p.buffer(sg->virtual_objects.vertices);
        VkDeviceSize offset = 0;
        vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
        vkCmdBindIndexBuffer(cmd, p.buffer(sg->virtual_objects.indices), 0, VK_INDEX_TYPE_UINT32);
        gi::RsmPush push = r.push;
        for (size_t i : r.draws) {
          const frame::DrawRange& d = sg->virtual_objects.draws[i];
          push.misc.y = d.material;
          vkCmdPushConstants(cmd, pipe->layout, pipe->stages, 0, sizeof push, &push);
          const frame::DrawRange::Lod l = d.lods.empty() || !r.lod
                                                  ? frame::DrawRange::Lod{d.first_index, d.index_count, 0.0f}
                                                  : d.lods[frame::MeshSet::select_lod(d, *r.lod)];
          vkCmdDrawIndexed(cmd, l.index_count, 1, l.first_index, d.vertex_offset, 0);
        }
        ctx.fn().cmd_end_rendering(cmd);
      });
}

std::vector<size_t> specular_draws(const frame::SceneGpu& scene, const std::vector<size_t>& objects, int kinds) {
  std::vector<size_t> out;
  for (size_t o : objects) {
    const frame::SceneGpu::DrawSpan span = scene.object_draws(o);
    for (size_t d = span.first; d < span.first + span.count; ++d) {
      const int m = scene.virtual_objects.draws[d].material;
      const int kind = m >= 0 && size_t(m) < scene.material_specular_kind.size() ? scene.material_specular_kind[size_t(m)] : 0;
      if (kind != 0 && (kinds & (1 << kind)) != 0) out.push_back(d);
    }
  }
  return out;
}

}  // namespace mrgi::specular
