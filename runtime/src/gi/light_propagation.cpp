#include "gi/light_propagation.h"

#include <string>

#include "gpu/shaders.h"

namespace mrgi::gi {
namespace {

struct InjectPush {
  glm::vec4 grid;
  glm::ivec4 sizes;
  glm::vec4 light;
  glm::vec4 colour;
  glm::vec4 options;  // x: VPL shift along the normal, cells
};
struct ResolvePush {
  glm::ivec4 cells;
};
struct LocalPush {
  glm::ivec4 sizes;  // used, allocated, steps
  glm::vec4 damping;
};
struct PropagatePush {
  glm::ivec4 cells;
  glm::vec4 damping;
};

VkExtent3D groups_3d(uint32_t n) { return {(n + 3) / 4, (n + 3) / 4, (n + 3) / 4}; }

}  // namespace

Expected<LightPropagationVolume> LightPropagationVolume::create(gpu::FrameGraph& graph, const LpvSettings& s) {
  if (s.resolution < 2 || s.resolution > 128)
    return fail(ErrorKind::BadUsage, "LpvSettings.resolution: must be 2..128 cells");
  if (!(s.negative_damping >= 0.0f && s.negative_damping <= 100.0f))
    return fail(ErrorKind::BadUsage, "LpvSettings.negative_damping: must be in [0, 100]");
  if (!(s.vpl_shift_cells >= 0.0f && s.vpl_shift_cells <= 1.0f))
    return fail(ErrorKind::BadUsage, "LpvSettings.vpl_shift_cells: must be in [0, 1]");
  if (!graph.context().image_float_atomic_add())
    return fail(ErrorKind::Device, "light propagation volume '" + s.name + "': device '" +
                                       graph.context().info().name +
                                       "' has no float atomics on images (VK_EXT_shader_atomic_float "
                                       "shaderImageFloat32AtomicAdd), which the VPL injection needs");
  LightPropagationVolume v;
  v.settings_ = s;
  const char* parts[3] = {" step A", " step B", " sum"};
  for (int i = 0; i < 3; ++i) {
    VolumeSettings vs;
    vs.name = s.name + parts[i];
    vs.resolution = s.resolution;
    vs.images = 3;
    vs.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    vs.history = i == 2;  // the accumulation: a frame that skips propagating reads the last one's
    auto vol = VoxelVolume::create(graph, vs);
    if (!vol) return vol.error();
    if (i < 2) {
      v.steps_[i].emplace(std::move(*vol));
    } else {
      v.sum_.emplace(std::move(*vol));
    }
  }
  gpu::BufferDesc bd;
  bd.name = s.name + " injection sums";
  bd.size = VkDeviceSize(s.resolution) * s.resolution * s.resolution * 12 * sizeof(float);
  bd.texel_format = VK_FORMAT_R32_SFLOAT;
  auto cells = graph.create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!cells) return cells.error();
  v.cells_ = *cells;
  const gpu::Context& ctx = graph.context();
  auto inject_spv = gpu::shader_spirv("gi/lpv_inject.comp");
  if (!inject_spv) return inject_spv.error();
  for (uint32_t mode = 0; mode < 4; ++mode) {  // lpv_inject.comp's kMode: one pipeline a mode
    auto inject = gpu::create_compute_pipeline(
        ctx, {s.name + " inject " + std::to_string(mode), *inject_spv, {}, sizeof(InjectPush), {mode}});
    if (!inject) return inject.error();
    v.inject_[mode] = gpu::PipelineHandle(ctx, std::move(*inject));
  }
  auto resolve = gpu::load_compute_pipeline(ctx, "gi/lpv_resolve.comp", {});
  if (!resolve) return resolve.error();
  v.resolve_ = std::move(*resolve);
  auto propagate = gpu::load_compute_pipeline(ctx, "gi/lpv_propagate.comp", {});
  if (!propagate) return propagate.error();
  v.propagate_ = std::move(*propagate);
  auto local = gpu::load_compute_pipeline(ctx, "gi/lpv_propagate_local.comp", {});
  if (!local) return local.error();
  v.propagate_local_ = std::move(*local);
  // The propagation pass pushes its own descriptors (one pass, many steps): by the shaders' names.
  auto find = [](const gpu::Pipeline& p, const std::string& name, uint32_t& out) -> Status {
    const gpu::ShaderBinding* b = p.interface.find(name);
    if (!b) return fail(ErrorKind::BadUsage, "light propagation volume: shader binding '" + name + "' not found");
    out = b->binding;
    return ok_status();
  };
  const char* ch = "rgb";
  MRGI_TRY(find(*v.resolve_, "cells", v.bindings_.cells));
  for (int c = 0; c < 3; ++c) {
    const std::string s_ = std::string("_") + ch[c];
    MRGI_TRY(find(*v.resolve_, "step" + s_, v.bindings_.resolve_step[c]));
    MRGI_TRY(find(*v.resolve_, "sum" + s_, v.bindings_.resolve_sum[c]));
    MRGI_TRY(find(*v.propagate_, "from" + s_, v.bindings_.from[c]));
    MRGI_TRY(find(*v.propagate_, "to" + s_, v.bindings_.to[c]));
    MRGI_TRY(find(*v.propagate_, "sum" + s_, v.bindings_.sum[c]));
  }
  return v;
}

Status LightPropagationVolume::set_cells(gpu::FrameGraph& graph, uint32_t cells) {
  if (cells < 2 || cells > settings_.resolution || settings_.resolution % cells != 0)
    return fail(ErrorKind::BadUsage, "light propagation volume '" + settings_.name + "': " + std::to_string(cells) +
                                         " cells per side: must divide the allocated " +
                                         std::to_string(settings_.resolution) + " and be at least 2");
  const uint32_t divisor = settings_.resolution / cells;
  for (auto& s : steps_) MRGI_TRY(s->set_divisor(graph, divisor));
  return sum_->set_divisor(graph, divisor);
}

void LightPropagationVolume::add_clear(gpu::FrameGraph& graph) const {
  const gpu::BufferHandle cells = cells_;
  const VkDeviceSize bytes = VkDeviceSize(this->cells()) * this->cells() * this->cells() * 12 * sizeof(float);
  graph.add_pass(
      settings_.name + " clear", gpu::PassKind::Transfer,
      [cells](gpu::PassBuilder& b) { b.write(cells, gpu::Access::TransferDst); },
      [cells, bytes](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(cells), 0, bytes, 0); });
}

void LightPropagationVolume::add_inject(gpu::FrameGraph& graph, const std::string& label, const RsmImages& rsm,
                                        const LpvLight& light, InjectKind kind, float sign,
                                        const RsmImages* other) const {
  // Without another map the map's own images stand in for the bindings (never read).
  const RsmImages o = other ? *other : rsm;
  const int mode = kind == InjectKind::Direct ? 1 : kind == InjectKind::IndirectFromReal ? 2 : other ? 3 : 0;
  const InjectPush push{glm::vec4(grid_.origin, grid_.cell_size),
                        glm::ivec4(int(cells()), int(rsm.width), int(rsm.height), 0),
                        glm::vec4(light.direction_or_position, light.positional ? 1.0f : 0.0f),
                        glm::vec4(light.colour, sign),
                        glm::vec4(settings_.vpl_shift_cells, 0.0f, 0.0f, 0.0f)};
  const gpu::BufferHandle cells = cells_;
  const gpu::Pipeline* pipe = &*inject_[mode];
  graph.add_shader_pass(
      settings_.name + " inject " + label, gpu::PassKind::Compute, *pipe,
      [rsm, cells, o](gpu::ShaderPassBuilder& b) {
        b.bind("rsm_position", rsm.position);
        b.bind("rsm_normal", rsm.normal);
        b.bind("rsm_flux", rsm.flux);
        b.bind("other_position", o.position);
        b.bind("other_normal", o.normal);
        b.bind("other_flux", o.flux);
        b.bind("cells", cells);
      },
      [pipe, push, rsm](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(rsm.width + 7) / 8, (rsm.height + 7) / 8, 1});
      });
}

void LightPropagationVolume::add_propagate(gpu::FrameGraph& graph, uint32_t steps) const {
  if (cells() <= kLocalCells && !settings_.one_step_a_dispatch) {
    // The reduced volumes: resolve and every step in one dispatch, a workgroup per colour channel
    // (lpv_propagate_local.comp).
    const uint32_t n = cells(), alloc = settings_.resolution;
    const VoxelVolume* sum = &*sum_;
    const LocalPush push{glm::ivec4(int(n), int(alloc), int(steps), 0),
                         glm::vec4(settings_.negative_damping, 0.0f, 0.0f, 0.0f)};
    const gpu::Pipeline* pipe = &*propagate_local_;
    graph.add_shader_pass(
        settings_.name + " propagate", gpu::PassKind::Compute, *propagate_local_,
        [this, sum](gpu::ShaderPassBuilder& b) {
          b.bind("cells", cells_);
          b.bind("sum_r", sum->image(0));
          b.bind("sum_g", sum->image(1));
          b.bind("sum_b", sum->image(2));
        },
        [pipe, push](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {3, 1, 1});  // a workgroup a channel
        });
    return;
  }
  // One graph pass for the resolve and every step: the steps' ping-pong images are the pass's
  // own, so the barriers between steps are recorded here (a compute-to-compute memory barrier
  // each) instead of as 2 + steps graph passes (the paper's Table 3 goes to 256 steps; per-pass
  // bookkeeping and, in profiling mode, one submission per pass would dominate). The steps'
  // descriptors are pushed by the names the shaders declare (bindings_, looked up at create()).
  const uint32_t n = cells(), alloc = settings_.resolution;
  const VoxelVolume* vols[2] = {&*steps_[0], &*steps_[1]};
  const VoxelVolume* sum = &*sum_;
  const gpu::BufferHandle cells = cells_;
  const gpu::Pipeline* resolve = &*resolve_;
  const gpu::Pipeline* propagate = &*propagate_;
  const Bindings bind = bindings_;
  const PropagatePush push{glm::ivec4(int(n), 0, 0, 0), glm::vec4(settings_.negative_damping, 0.0f, 0.0f, 0.0f)};
  graph.add_pass(
      settings_.name + " propagate", gpu::PassKind::Compute,
      [vols, sum, cells](gpu::PassBuilder& b) {
        b.read(cells, gpu::Access::StorageRead);
        for (uint32_t c = 0; c < 3; ++c) {
          b.write(vols[0]->image(c), gpu::Access::StorageReadWrite);
          b.write(vols[1]->image(c), gpu::Access::StorageReadWrite);
          b.write(sum->image(c), gpu::Access::StorageReadWrite);
        }
      },
      [=](VkCommandBuffer cmd, gpu::PassContext& p) {
        const gpu::Context& ctx = p.context();
        VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        mb.srcStageMask = mb.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        mb.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &mb;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, resolve->pipeline);
        gpu::DescriptorPush rp;
        rp.storage_texel_buffer(bind.cells, p.texel_view(cells));
        for (uint32_t c = 0; c < 3; ++c) {
          rp.storage_image(bind.resolve_step[c], p.view(vols[0]->image(c)));
          rp.storage_image(bind.resolve_sum[c], p.view(sum->image(c)));
        }
        rp.push(ctx, cmd, *resolve);
        const ResolvePush rpush{glm::ivec4(int(n), int(alloc), 0, 0)};
        gpu::push_and_dispatch(cmd, *resolve, &rpush, sizeof rpush, groups_3d(n + 1));  // + the border
        if (steps == 0) return;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, propagate->pipeline);
        for (uint32_t i = 0; i < steps; ++i) {
          ctx.fn().cmd_pipeline_barrier2(cmd, &dep);
          const VoxelVolume* from = vols[i % 2];
          const VoxelVolume* to = vols[(i + 1) % 2];
          gpu::DescriptorPush pp;
          for (uint32_t c = 0; c < 3; ++c) {
            pp.storage_image(bind.from[c], p.view(from->image(c)));
            pp.storage_image(bind.to[c], p.view(to->image(c)));
            pp.storage_image(bind.sum[c], p.view(sum->image(c)));
          }
          pp.push(ctx, cmd, *propagate);
          gpu::push_and_dispatch(cmd, *propagate, &push, sizeof push, groups_3d(n));
        }
      });
}

}  // namespace mrgi::gi
