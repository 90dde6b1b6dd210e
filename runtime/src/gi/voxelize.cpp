#include "gi/voxelize.h"

namespace mrgi::gi {
namespace {

struct VoxelizeMeshPush {
  glm::vec4 region;
  glm::ivec4 range;  // cells, first index, triangles, vertex offset
};
struct VoxelizeDepthPush {
  glm::vec4 region;
  glm::ivec4 sizes;  // cells, width, height
};
struct VoxelizeResolvePush {
  glm::ivec4 cells;
};

}  // namespace

Expected<Voxelizer> Voxelizer::create(gpu::FrameGraph& graph, const VoxelizeSettings& s) {
  if (s.resolution < 2 || s.resolution > 256)
    return fail(ErrorKind::BadUsage, "VoxelizeSettings.resolution: must be 2..256 cells");
  if (!graph.context().image_float_atomic_add())
    return fail(ErrorKind::Device, "voxeliser '" + s.name + "': device '" + graph.context().info().name +
                                       "' has no float atomics on images (VK_EXT_shader_atomic_float "
                                       "shaderImageFloat32AtomicAdd), which the voxelisation needs");
  Voxelizer v;
  v.settings_ = s;
  VolumeSettings vs;
  vs.name = s.name + " visibility";
  vs.resolution = s.resolution;
  vs.images = 1;
  vs.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  vs.mip_chain = true;
  vs.history = true;  // a frame that does not re-voxelise traces what the last one left
  auto vol = VoxelVolume::create(graph, vs);
  if (!vol) return vol.error();
  v.volume_.emplace(std::move(*vol));
  gpu::BufferDesc bd;
  bd.name = s.name + " sums";
  bd.size = VkDeviceSize(s.resolution) * s.resolution * s.resolution * 4 * sizeof(float);
  bd.texel_format = VK_FORMAT_R32_SFLOAT;
  auto sums = graph.create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!sums) return sums.error();
  v.sums_ = *sums;
  const gpu::Context& ctx = graph.context();
  auto mesh = gpu::load_compute_pipeline(ctx, "gi/voxelize_mesh.comp", {});
  if (!mesh) return mesh.error();
  v.mesh_ = std::move(*mesh);
  auto depth = gpu::load_compute_pipeline(ctx, "gi/voxelize_depth.comp", {});
  if (!depth) return depth.error();
  v.depth_ = std::move(*depth);
  auto resolve = gpu::load_compute_pipeline(ctx, "gi/voxelize_resolve.comp", {});
  if (!resolve) return resolve.error();
  v.resolve_ = std::move(*resolve);
  return v;
}

Status Voxelizer::set_cells(gpu::FrameGraph& graph, uint32_t cells) {
  return volume_->set_cells(graph, cells, "voxeliser");
}

void Voxelizer::add_clear(gpu::FrameGraph& graph) {
  volume_->add_clear_if_resized(graph);  // resolve writes the used corner of each level
  const gpu::BufferHandle sums = sums_;
  const VkDeviceSize bytes = VkDeviceSize(cells()) * cells() * cells() * 4 * sizeof(float);
  graph.add_pass(
      settings_.name + " clear", gpu::PassKind::Transfer,
      [sums](gpu::PassBuilder& b) { b.write(sums, gpu::Access::TransferDst); },
      [sums, bytes](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(sums), 0, bytes, 0); });
}

void Voxelizer::add_mesh(gpu::FrameGraph& graph, const std::string& label, gpu::BufferHandle vertices,
                         gpu::BufferHandle indices, const std::vector<TriangleRange>& ranges) const {
  const gpu::Pipeline* pipe = &*mesh_;
  const gpu::BufferHandle sums = sums_;
  const glm::vec4 region(region_.origin, region_.voxel_size);
  const int n = int(cells());
  graph.add_shader_pass(
      settings_.name + " voxelize " + label, gpu::PassKind::Compute, *pipe,
      [vertices, indices, sums](gpu::ShaderPassBuilder& b) {
        b.bind("Vertices", vertices);
        b.bind("Indices", indices);
        b.bind("cells", sums);
      },
      [pipe, region, n, ranges](VkCommandBuffer cmd, gpu::PassContext&) {
        for (const TriangleRange& r : ranges) {
          const uint32_t triangles = r.index_count / 3;
          if (triangles == 0) continue;
          const VoxelizeMeshPush push{region, glm::ivec4(n, int(r.first_index), int(triangles), r.vertex_offset)};
          gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(triangles + 63) / 64, 1, 1});
        }
      });
}

void Voxelizer::add_depth_surface(gpu::FrameGraph& graph, const std::string& label, gpu::ImageHandle position,
                                  gpu::ImageHandle normal, uint32_t width, uint32_t height, uint32_t stride) const {
  const gpu::Pipeline* pipe = &*depth_;
  const gpu::BufferHandle sums = sums_;
  stride = std::max(stride, 1u);
  const VoxelizeDepthPush push{glm::vec4(region_.origin, region_.voxel_size),
                               glm::ivec4(int(cells()), int(width), int(height), int(stride))};
  const uint32_t quads_x = (std::max(width, 2u) - 2) / stride + 1, quads_y = (std::max(height, 2u) - 2) / stride + 1;
  graph.add_shader_pass(
      settings_.name + " voxelize " + label, gpu::PassKind::Compute, *pipe,
      [position, normal, sums](gpu::ShaderPassBuilder& b) {
        b.bind("real_position", position);
        b.bind("real_normal", normal);
        b.bind("cells", sums);
      },
      [pipe, push, quads_x, quads_y](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(quads_x + 7) / 8, (quads_y + 7) / 8, 1});
      });
}

void Voxelizer::add_resolve(gpu::FrameGraph& graph) {
  const gpu::Pipeline* pipe = &*resolve_;
  const gpu::BufferHandle sums = sums_;
  const gpu::ImageHandle image = volume_->image(0);
  const uint32_t n = cells();
  const VoxelizeResolvePush push{glm::ivec4(int(n), 0, 0, 0)};
  graph.add_shader_pass(
      settings_.name + " resolve", gpu::PassKind::Compute, *pipe,
      [this, sums, image](gpu::ShaderPassBuilder& b) {
        b.bind("cells", sums);
        b.bind("visibility", image, 0);
        volume_->keep_cleared_margin(b);
      },
      [pipe, push, n](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(n + 3) / 4, (n + 3) / 4, (n + 3) / 4});
      });
  volume_->add_mip_chain(graph);
}

}  // namespace mrgi::gi
