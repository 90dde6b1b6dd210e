#include "gi/voxel_light.h"

#include <numbers>

#include "gpu/shaders.h"

namespace mrgi::gi {
namespace {

struct VoxelInjectPush {
  glm::vec4 region;
  glm::ivec4 sizes;  // cells, map width, height
  glm::vec4 sign;
};
struct VoxelSurfacePush {
  glm::vec4 region;
  glm::ivec4 range;     // cells, first index, triangles, vertex offset
  glm::ivec4 material;  // material, emission on
};
struct VoxelLightResolvePush {
  glm::ivec4 cells;
  glm::vec4 scale;
};

}  // namespace

Expected<VoxelLight> VoxelLight::create(gpu::FrameGraph& graph, const VoxelLightSettings& s) {
  if (s.resolution < 2 || s.resolution > 256)
    return fail(ErrorKind::BadUsage, "VoxelLightSettings.resolution: must be 2..256 cells");
  if (!graph.context().image_float_atomic_add())
    return fail(ErrorKind::Device, "voxel light '" + s.name + "': device '" + graph.context().info().name +
                                       "' has no float atomics on images (VK_EXT_shader_atomic_float "
                                       "shaderImageFloat32AtomicAdd), which the injection needs");
  VoxelLight v;
  v.settings_ = s;
  VolumeSettings vs;
  vs.name = s.name;
  vs.resolution = s.resolution;
  vs.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  vs.mip_chain = true;
  vs.history = true;  // a frame that does not re-inject traces what the last one left
  auto vol = VoxelVolume::create(graph, vs);
  if (!vol) return vol.error();
  v.volume_.emplace(std::move(*vol));
  gpu::BufferDesc bd;
  bd.name = s.name + " sums";
  bd.size = VkDeviceSize(s.resolution) * s.resolution * s.resolution * 3 * sizeof(float);
  bd.texel_format = VK_FORMAT_R32_SFLOAT;
  auto sums = graph.create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!sums) return sums.error();
  v.sums_ = *sums;
  const gpu::Context& ctx = graph.context();
  auto spv = gpu::shader_spirv("gi/voxel_inject.comp");
  if (!spv) return spv.error();
  for (uint32_t pair = 0; pair < 2; ++pair) {  // voxel_inject.comp's kDeltaPair: one pipeline each
    auto p = gpu::create_compute_pipeline(ctx, {s.name + " inject " + std::to_string(pair), *spv, {}, sizeof(VoxelInjectPush), {pair}});
    if (!p) return p.error();
    v.inject_[pair] = gpu::PipelineHandle(ctx, std::move(*p));
  }
  auto resolve = gpu::load_compute_pipeline(ctx, "gi/voxel_light_resolve.comp", {});
  if (!resolve) return resolve.error();
  v.resolve_ = std::move(*resolve);
  if (s.surfaces) {
    auto surfaces = gpu::load_compute_pipeline(ctx, "gi/voxel_inject_surfaces.comp", {});
    if (!surfaces) return surfaces.error();
    v.surfaces_ = std::move(*surfaces);
  }
  return v;
}

Status VoxelLight::set_cells(gpu::FrameGraph& graph, uint32_t cells) {
  return volume_->set_cells(graph, cells, "voxel light");
}

void VoxelLight::add_clear(gpu::FrameGraph& graph) {
  volume_->add_clear_if_resized(graph);  // resolve writes the used corner of each level
  const gpu::BufferHandle sums = sums_;
  const VkDeviceSize bytes = VkDeviceSize(cells()) * cells() * cells() * 3 * sizeof(float);
  graph.add_pass(
      settings_.name + " clear", gpu::PassKind::Transfer,
      [sums](gpu::PassBuilder& b) { b.write(sums, gpu::Access::TransferDst); },
      [sums, bytes](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(sums), 0, bytes, 0); });
}

void VoxelLight::add_inject(gpu::FrameGraph& graph, const std::string& label, const RsmImages& rsm, float sign,
                            const RsmImages* other) const {
  const RsmImages o = other ? *other : rsm;  // without a pair the map stands in (never read)
  const gpu::Pipeline* pipe = &*inject_[other ? 1 : 0];
  const gpu::BufferHandle sums = sums_;
  const VoxelInjectPush push{glm::vec4(region_.origin, region_.voxel_size),
                        glm::ivec4(int(cells()), int(rsm.width), int(rsm.height), 0), glm::vec4(sign, 0.0f, 0.0f, 0.0f)};
  graph.add_shader_pass(
      settings_.name + " inject " + label, gpu::PassKind::Compute, *pipe,
      [rsm, o, sums](gpu::ShaderPassBuilder& b) {
        b.bind("rsm_position", rsm.position);
        b.bind("rsm_flux", rsm.flux);
        b.bind("other_position", o.position);
        b.bind("other_flux", o.flux);
        b.bind("cells", sums);
      },
      [pipe, push, rsm](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(rsm.width + 7) / 8, (rsm.height + 7) / 8, 1});
      });
}

void VoxelLight::add_inject_surfaces(gpu::FrameGraph& graph, const std::string& label,
                                     const SurfaceLightSource& source) const {
  const gpu::Pipeline* pipe = &*surfaces_;
  const gpu::BufferHandle sums = sums_;
  const glm::vec4 region(region_.origin, region_.voxel_size);
  const int n = int(cells());
  const VkSampler linear = graph.context().samplers().linear_repeat;
  graph.add_shader_pass(
      settings_.name + " inject " + label, gpu::PassKind::Compute, *pipe,
      [src = &source, sums, linear](gpu::ShaderPassBuilder& b) {
        b.bind("Vertices", src->vertices);
        b.bind("Indices", src->indices);
        b.bind("Materials", src->materials);
        b.bind_sampled("base_color_maps", src->base_color_maps, linear);
        b.bind("LightUbo", src->light_set);
        b.bind("cells", sums);
      },
      [pipe, region, n, src = &source](VkCommandBuffer cmd, gpu::PassContext&) {
        for (const SurfaceLightSource::Range& r : src->ranges) {
          const uint32_t triangles = r.index_count / 3;
          if (triangles == 0) continue;
          const VoxelSurfacePush push{region, glm::ivec4(n, int(r.first_index), int(triangles), r.vertex_offset),
                                      glm::ivec4(r.material, src->emission ? 1 : 0, 0, 0)};
          gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(triangles + 63) / 64, 1, 1});
        }
      });
}

void VoxelLight::add_resolve(gpu::FrameGraph& graph) {
  const gpu::Pipeline* pipe = &*resolve_;
  const gpu::BufferHandle sums = sums_;
  const gpu::ImageHandle image = volume_->image(0);
  const uint32_t n = cells();
  const float s = region_.voxel_size;
  const VoxelLightResolvePush push{glm::ivec4(int(n), 0, 0, 0), glm::vec4(1.0f / (std::numbers::pi_v<float> * s * s), 0.0f, 0.0f, 0.0f)};
  graph.add_shader_pass(
      settings_.name + " resolve", gpu::PassKind::Compute, *pipe,
      [this, sums, image](gpu::ShaderPassBuilder& b) {
        b.bind("cells", sums);
        b.bind("light", image, 0);
        volume_->keep_cleared_margin(b);
      },
      [pipe, push, n](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(n + 3) / 4, (n + 3) / 4, (n + 3) / 4});
      });
  volume_->add_mip_chain(graph);
}

}  // namespace mrgi::gi
