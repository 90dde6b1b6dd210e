#include "gi/vpl_bounce.h"

#include "common/vpl.glsl"
#include "gpu/shaders.h"

namespace mrgi::gi {
namespace {

// vpl_bounce.comp Params.
struct BouncePush {
  glm::ivec4 source;
  glm::ivec4 points;
  glm::vec4 sphere;
  glm::vec4 test;
  glm::vec4 camera;
};

}  // namespace

Expected<VplBounce> VplBounce::create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                      const BounceGBuffer& gbuffer, const VplBounceSettings& s) {
  if (s.name.empty()) return fail(ErrorKind::BadUsage, "VplBounceSettings.name: must not be empty");
  if (s.max_slots < 1 || s.max_slots > 1024) return fail(ErrorKind::BadUsage, "VplBounceSettings.max_slots: must be 1..1024");
  VplBounce b;
  b.settings_ = s;
  b.scene_ = &scene;
  b.gbuffer_ = gbuffer;
  // Transfer source: tests read the slots back.
  auto buffer = graph.create_buffer({s.name + " slots", VkDeviceSize(s.max_slots) * sizeof(shader::Vpl)},
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!buffer) return buffer.error();
  b.bounce_ = *buffer;
  auto spv = gpu::shader_spirv("gi/vpl_bounce.comp");
  if (!spv) return spv.error();
  auto p = gpu::create_compute_pipeline(graph.context(), {s.name, *spv, {}, 0, {s.glossy ? 1u : 0u}});
  if (!p) return p.error();
  b.pipeline_ = gpu::PipelineHandle(graph.context(), std::move(*p));
  return b;
}

Status VplBounce::add_bounce(gpu::FrameGraph& graph, gpu::BufferHandle previous_vpls, gpu::ImageHandle previous_ism,
                             const BounceFrame& f) const {
  if (f.slots < 1 || f.slots > settings_.max_slots)
    return fail(ErrorKind::BadUsage, "vpl bounce '" + settings_.name + "': " + std::to_string(f.slots) + " slots, 1.." +
                                         std::to_string(settings_.max_slots) + " allocated");
  if (f.source_vpls < 1 || f.source_vpls > kMaxSources || f.source_ism_size < 1 || f.source_tiles_per_row < 1)
    return fail(ErrorKind::BadUsage, "vpl bounce '" + settings_.name + "': the previous frame's VPLs (1.." +
                                         std::to_string(kMaxSources) + ") and ISM layout must be given");
  if (!(f.radius > 0.0f) || !(f.focal_px.x > 0.0f) || !(f.focal_px.y > 0.0f) || !(f.clamp_m > 0.0f))
    return fail(ErrorKind::BadUsage, "vpl bounce '" + settings_.name + "': radius, focal lengths and clamp must be > 0");
  const VkExtent2D g = graph.extent(gbuffer_.position);
  // The objects present this frame (frame::SceneGpu::virtual_triangles, current for its slot).
  const frame::VirtualTriangles& triangles = scene_->virtual_triangles();
  const BouncePush push{glm::ivec4(int(f.source_vpls), int(f.source_ism_size), int(f.source_tiles_per_row), int(f.slots)),
                        glm::ivec4(int(g.width), int(g.height), int(triangles.triangles), int(triangles.range_count)),
                        glm::vec4(f.centre, f.radius), glm::vec4(f.clamp_m, f.bias_relative, f.bias_m, 0.0f),
                        glm::vec4(f.focal_px, 0.0f, 0.0f)};
  const gpu::Pipeline* pipe = &*pipeline_;
  const frame::SceneGpu* sg = scene_;
  const frame::VirtualTriangles tri = triangles;
  const BounceGBuffer gb = gbuffer_;
  const gpu::BufferHandle out = bounce_;
  const VkSampler linear = graph.context().samplers().linear_repeat;
  const uint32_t slots = f.slots;
  graph.add_shader_pass(
      settings_.name, gpu::PassKind::Compute, *pipeline_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("Vpls", previous_vpls);
        b.bind("ism_distances", previous_ism, 0);
        b.bind("real_position", gb.position);
        b.bind("real_normal", gb.normal);
        b.bind("real_albedo", gb.albedo);
        b.bind("Vertices", sg->virtual_objects.vertices);
        b.bind("Indices", sg->virtual_objects.indices);
        b.bind("Ranges", tri.ranges);
        b.bind("RangeMaterials", tri.materials);
        b.bind("Materials", sg->materials);
        b.bind_sampled("base_color_maps", sg->base_color_maps, linear);
        b.bind("Bounce", out);
      },
      [pipe, push, slots](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {slots, 1, 1});
      });
  return ok_status();
}

}  // namespace mrgi::gi
