#include "gi/vpl.h"

#include "specular/photon.glsl"

#include <bit>
#include <string>

#include "common/vpl.glsl"
#include "gpu/shaders.h"

namespace mrgi::gi {
namespace {

Error vpl_setting_error(const std::string& field, const std::string& rule) {
  return fail(ErrorKind::BadUsage, "VplSettings." + field + ": " + rule);
}

}  // namespace

Expected<VplSampler> VplSampler::create(gpu::FrameGraph& graph, const VplSettings& s) {
  if (s.name.empty()) return vpl_setting_error("name", "must not be empty");
  if (s.max_vpls < 1 || s.max_vpls > 4096) return vpl_setting_error("max_vpls", "must be 1..4096 slots");
  if (!std::has_single_bit(s.map_size) || s.map_size < 16 || s.map_size > 4096)
    return vpl_setting_error("map_size", "must be a power of two, 16..4096 texels");
  VplSampler v;
  v.settings_ = s;
  while ((s.map_size >> v.levels_) > 0) ++v.levels_;
  gpu::ImageDesc d;
  d.name = s.name + " importance";
  d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  d.size_mode = gpu::SizeMode::Absolute;
  d.width = d.height = s.map_size;
  d.mip_levels = v.levels_;
  auto pyramid = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
  if (!pyramid) return pyramid.error();
  v.pyramid_ = *pyramid;
  gpu::BufferDesc bd{s.name + " slots", VkDeviceSize(s.max_vpls) * sizeof(shader::Vpl)};
  bd.history = s.history;
  auto buffer = graph.create_buffer(bd,
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!buffer) return buffer.error();
  v.vpls_ = *buffer;
  auto none = graph.create_buffer({s.name + " no photons", sizeof(shader::Photon)}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!none) return none.error();
  v.no_photons_ = *none;
  const gpu::Context& ctx = graph.context();
  auto ip = gpu::load_compute_pipeline(ctx, "gi/vpl_importance.comp", {});
  if (!ip) return ip.error();
  v.importance_ = std::move(*ip);
  auto dp = gpu::load_compute_pipeline(ctx, "gi/importance_downsample.comp", {});
  if (!dp) return dp.error();
  v.downsample_ = std::move(*dp);
  auto sample_spv = gpu::shader_spirv("gi/vpl_sample.comp");
  if (!sample_spv) return sample_spv.error();
  auto sp = gpu::create_compute_pipeline(ctx, {s.name + " sample", *sample_spv, {}, 0, {s.glossy ? 1u : 0u}});
  if (!sp) return sp.error();
  v.sample_ = gpu::PipelineHandle(ctx, std::move(*sp));
  auto cp = gpu::load_compute_pipeline(ctx, "gi/vpl_copy.comp", {});
  if (!cp) return cp.error();
  v.copy_ = std::move(*cp);
  return v;
}

void VplSampler::add_clear(gpu::FrameGraph& graph) const {
  const gpu::BufferHandle b = vpls_;
  graph.add_pass(
      settings_.name + " clear", gpu::PassKind::Transfer, [b](gpu::PassBuilder& p) { p.write(b, gpu::Access::TransferDst); },
      [b](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(b), 0, VK_WHOLE_SIZE, 0); });
}

Status VplSampler::add_copy(gpu::FrameGraph& graph, const std::string& id, gpu::BufferHandle source, uint32_t first,
                            uint32_t count) const {
  if (count == 0 || first + count > settings_.max_vpls)
    return fail(ErrorKind::BadUsage, "vpl '" + settings_.name + "': copy into slots " + std::to_string(first) + " + " +
                                         std::to_string(count) + " outside the " + std::to_string(settings_.max_vpls) +
                                         " allocated (none is an error too)");
  const gpu::Pipeline* cp = &*copy_;
  const gpu::BufferHandle vpls = vpls_;
  const glm::ivec4 slots(int(first), int(count), 0, 0);
  graph.add_shader_pass(
      settings_.name + " copy " + id, gpu::PassKind::Compute, *copy_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("Source", source);
        b.bind_over("Vpls", vpls);  // the other slots stay
      },
      [cp, slots, count](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *cp, &slots, sizeof slots, {(count + 63) / 64, 1, 1});
      });
  return ok_status();
}

Status VplSampler::add_sample(gpu::FrameGraph& graph, const std::string& id, const RsmImages& rho, const RsmImages& mu,
                              bool real_lamp, const VplLamp& lamp, uint32_t first, uint32_t count,
                              const VplCaustics* caustics) {
  const uint32_t side = rho.width;
  if (rho.height != side || mu.width != side || mu.height != side || !std::has_single_bit(side) || side > settings_.map_size)
    return fail(ErrorKind::BadUsage, "vpl '" + settings_.name + "': the maps must be square, equal, a power of two and at most " +
                                         std::to_string(settings_.map_size) + " texels per side (got " +
                                         std::to_string(rho.width) + "x" + std::to_string(rho.height) + ")");
  if (count == 0 || first + count > settings_.max_vpls)
    return fail(ErrorKind::BadUsage, "vpl '" + settings_.name + "': slots " + std::to_string(first) + " + " +
                                         std::to_string(count) + " outside the " + std::to_string(settings_.max_vpls) +
                                         " allocated (none is an error too)");
  MRGI_TRY(graph.set_extent_divisor(pyramid_, settings_.map_size / side));
  uint32_t top = 0;
  while ((side >> top) > 1) ++top;
  const gpu::ImageHandle pyramid = pyramid_;
  const gpu::Pipeline* ip = &*importance_;
  const glm::ivec4 isize(int(side), real_lamp ? 1 : 0, 0, 0);
  graph.add_shader_pass(
      settings_.name + " importance " + id, gpu::PassKind::Compute, *importance_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("rho_position", rho.position);
        b.bind("rho_flux", rho.flux);
        b.bind("mu_position", mu.position);
        b.bind("mu_flux", mu.flux);
        b.bind("importance", pyramid, 0);
      },
      [ip, isize, side](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *ip, &isize, sizeof isize, {(side + 7) / 8, (side + 7) / 8, 1});
      });
  const gpu::Pipeline* dp = &*downsample_;
  for (uint32_t m = 1; m <= top; ++m) {
    const uint32_t s = side >> m;
    const glm::ivec4 dsize(int(s), 0, 0, 0);
    graph.add_shader_pass(
        settings_.name + " pyramid " + id + " " + std::to_string(m), gpu::PassKind::Compute, *downsample_,
        [pyramid, m](gpu::ShaderPassBuilder& b) {
          b.bind("finer", pyramid, m - 1);
          b.bind("coarser", pyramid, m);
        },
        [dp, dsize, s](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::push_and_dispatch(cmd, *dp, &dsize, sizeof dsize, {(s + 7) / 8, (s + 7) / 8, 1});
        });
  }
  const gpu::Pipeline* sp = &*sample_;
  const gpu::BufferHandle vpls = vpls_;
  struct {
    glm::ivec4 slots;
    glm::vec4 lamp, colour;
    glm::mat4 caustic_view_proj;
    glm::ivec4 caustic;  // x photon map side (0: no caustics)
  } const push{glm::ivec4(int(first), int(count), int(top), real_lamp ? 1 : 0), lamp.light, glm::vec4(lamp.colour, 0.0f),
               caustics ? caustics->view_proj : glm::mat4(1.0f), glm::ivec4(caustics ? int(caustics->size) : 0, 0, 0, 0)};
  static_assert(sizeof(push) == 128, "the guaranteed push-constant size");
  const gpu::BufferHandle photons = caustics ? caustics->photons : no_photons_;
  const VkSampler nearest = graph.context().samplers().nearest_clamp;
  graph.add_shader_pass(
      settings_.name + " sample " + id, gpu::PassKind::Compute, *sample_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind_sampled("importance", pyramid, nearest);
        b.bind("rho_position", rho.position);
        b.bind("rho_normal", rho.normal);
        b.bind("rho_flux", rho.flux);
        b.bind("mu_position", mu.position);
        b.bind("mu_normal", mu.normal);
        b.bind("mu_flux", mu.flux);
        b.bind_over("Vpls", vpls);  // other pairs' slots and the clear stay
        b.bind("Photons", photons);
      },
      [sp, push, count](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *sp, &push, sizeof push, {(count + 63) / 64, 1, 1});
      });
  return ok_status();
}

}  // namespace mrgi::gi
