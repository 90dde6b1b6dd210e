#include "gi/ism.h"

#include <cmath>
#include <cstring>
#include <bit>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mrgi::gi {
namespace {

Error ism_setting_error(const std::string& field, const std::string& rule) {
  return fail(ErrorKind::BadUsage, "IsmSettings." + field + ": " + rule);
}

// gi/ism_common.glsl IsmParams.
struct IsmPush {
  glm::ivec4 tiles;
  glm::ivec4 source;
  glm::vec4 camera;
};

constexpr uint32_t kPullLevels = 2;  // pull-push depth: holes up to about 2^2 texels wide fill

}  // namespace

uint32_t ImperfectShadowMaps::tiles_per_row(uint32_t vpls) const {
  uint32_t t = 1;
  while (t * t < vpls) ++t;
  return t;
}

Expected<ImperfectShadowMaps> ImperfectShadowMaps::create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                                          gpu::ImageHandle real_position, gpu::ImageHandle real_normal,
                                                          const IsmSettings& s) {
  if (s.name.empty()) return ism_setting_error("name", "must not be empty");
  if (s.max_vpls < 1 || s.max_vpls > 4096) return ism_setting_error("max_vpls", "must be 1..4096");
  if (!std::has_single_bit(s.map_size) || s.map_size < 8 || s.map_size > 512)
    return ism_setting_error("map_size", "must be a power of two, 8..512 texels");
  ImperfectShadowMaps m;
  m.settings_ = s;
  m.scene_ = &scene;
  m.real_position_ = real_position;
  m.real_normal_ = real_normal;
  const uint32_t atlas = m.tiles_per_row(s.max_vpls) * s.map_size;
  auto image = [&](const std::string& what, VkFormat format, uint32_t levels, bool history = false) {
    gpu::ImageDesc d;
    d.name = s.name + " " + what;
    d.history = history;
    d.format = format;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = d.height = atlas;
    d.mip_levels = levels;
    // Transfer source: tests and debug tools read the maps back.
    return graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  };
  auto sr = image("splat real", VK_FORMAT_R32_UINT, 1);
  if (!sr) return sr.error();
  m.splat_real_ = *sr;
  auto sv = image("splat virtual", VK_FORMAT_R32_UINT, 1);
  if (!sv) return sv.error();
  m.splat_virtual_ = *sv;
  auto dist = image("distances", VK_FORMAT_R32G32_SFLOAT, kPullLevels + 1, s.history);
  if (!dist) return dist.error();
  m.distances_ = *dist;

  const gpu::Context& ctx = graph.context();
  struct Load {
    const char* shader;
    gpu::PipelineHandle* out;
  };
  for (const Load& l : {Load{"gi/ism_clear.comp", &m.clear_}, Load{"gi/ism_splat_real.comp", &m.splat_real_pipe_},
                        Load{"gi/ism_splat_virtual.comp", &m.splat_virtual_pipe_},
                        Load{"gi/ism_pull_splat.comp", &m.pull_splat_}, Load{"gi/ism_pull.comp", &m.pull_},
                        Load{"gi/ism_push.comp", &m.push_}, Load{"gi/ism_resolve.comp", &m.resolve_}}) {
    auto p = gpu::load_compute_pipeline(ctx, l.shader, {});
    if (!p) return p.error();
    *l.out = std::move(*p);
  }
  return m;
}

Status ImperfectShadowMaps::add_build(gpu::FrameGraph& graph, gpu::BufferHandle vpls, const IsmFrame& f) {
  if (f.vpls < 1 || f.vpls > settings_.max_vpls)
    return fail(ErrorKind::BadUsage, "ism '" + settings_.name + "': " + std::to_string(f.vpls) + " VPLs, 1.." +
                                         std::to_string(settings_.max_vpls) + " allocated");
  if (!std::has_single_bit(f.map_size) || f.map_size > settings_.map_size || f.map_size < (1u << kPullLevels))
    return fail(ErrorKind::BadUsage, "ism '" + settings_.name + "': map size " + std::to_string(f.map_size) +
                                         " must be a power of two, " + std::to_string(1u << kPullLevels) + ".." +
                                         std::to_string(settings_.map_size));
  if (f.points_per_vpl < 1 || !(f.focal_px.x > 0.0f) || !(f.focal_px.y > 0.0f))
    return fail(ErrorKind::BadUsage, "ism '" + settings_.name + "': points per VPL and focal lengths must be > 0");
  const uint32_t row = tiles_per_row(f.vpls);
  const uint32_t side = row * f.map_size;
  const VkExtent2D g = graph.extent(real_position_);
  const gpu::ImageHandle sr = splat_real_, sv = splat_virtual_, dist = distances_;
  const glm::ivec4 used(int(side), 0, 0, 0);
  auto groups = [](uint32_t n) { return (n + 7) / 8; };

  const gpu::Pipeline* clear = &*clear_;
  graph.add_shader_pass(
      settings_.name + " clear", gpu::PassKind::Compute, *clear_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("splat_real", sr);
        b.bind("splat_virtual", sv);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *clear, &used, sizeof used, {groups(side), groups(side), 1});
      });
  const uint32_t points = f.vpls * f.points_per_vpl;
  const IsmPush real_push{glm::ivec4(int(f.vpls), int(f.map_size), int(row), int(f.points_per_vpl)),
                          glm::ivec4(int(g.width), int(g.height), 0, 0), glm::vec4(f.focal_px, 0.0f, 0.0f)};
  const gpu::Pipeline* splat_real = &*splat_real_pipe_;
  const gpu::ImageHandle position = real_position_, normal = real_normal_;
  graph.add_shader_pass(
      settings_.name + " splat real", gpu::PassKind::Compute, *splat_real_pipe_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("Vpls", vpls);
        b.bind("real_position", position);
        b.bind("real_normal", normal);
        b.bind("splat", sr);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *splat_real, &real_push, sizeof real_push, {(points + 63) / 64, 1, 1});
      });
  // The objects present this frame (frame::SceneGpu::virtual_triangles, current for its slot).
  const frame::VirtualTriangles& tri = scene_->virtual_triangles();
  if (tri.triangles > 0) {
    const IsmPush virtual_push{real_push.tiles, glm::ivec4(int(tri.triangles), int(tri.range_count), 0, 0),
                               glm::vec4(0.0f)};
    const gpu::Pipeline* splat_virtual = &*splat_virtual_pipe_;
    const frame::MeshSet& mesh = scene_->virtual_objects;
    const gpu::BufferHandle vertices = mesh.vertices, indices = mesh.indices, ranges = tri.ranges;
    graph.add_shader_pass(
        settings_.name + " splat virtual", gpu::PassKind::Compute, *splat_virtual_pipe_,
        [=](gpu::ShaderPassBuilder& b) {
          b.bind("Vpls", vpls);
          b.bind("Vertices", vertices);
          b.bind("Indices", indices);
          b.bind("Ranges", ranges);
          b.bind("splat", sv);
        },
        [=](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::push_and_dispatch(cmd, *splat_virtual, &virtual_push, sizeof virtual_push, {(points + 63) / 64, 1, 1});
        });
  }
  const gpu::Pipeline* pull_splat = &*pull_splat_;
  const glm::ivec4 level1(int(side / 2), 0, 0, 0), level2(int(side / 4), 0, 0, 0);
  graph.add_shader_pass(
      settings_.name + " pull 1", gpu::PassKind::Compute, *pull_splat_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("splat_real", sr);
        b.bind("splat_virtual", sv);
        b.bind("coarser", dist, 1);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pull_splat, &level1, sizeof level1, {groups(side / 2), groups(side / 2), 1});
      });
  const gpu::Pipeline* pull = &*pull_;
  graph.add_shader_pass(
      settings_.name + " pull 2", gpu::PassKind::Compute, *pull_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("finer", dist, 1);
        b.bind("coarser", dist, 2);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pull, &level2, sizeof level2, {groups(side / 4), groups(side / 4), 1});
      });
  const gpu::Pipeline* push = &*push_;
  graph.add_shader_pass(
      settings_.name + " push 1", gpu::PassKind::Compute, *push_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("coarser", dist, 2);
        b.bind("finer", dist, 1);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *push, &level1, sizeof level1, {groups(side / 2), groups(side / 2), 1});
      });
  const gpu::Pipeline* resolve = &*resolve_;
  graph.add_shader_pass(
      settings_.name + " resolve", gpu::PassKind::Compute, *resolve_,
      [=](gpu::ShaderPassBuilder& b) {
        b.bind("splat_real", sr);
        b.bind("splat_virtual", sv);
        b.bind("filled", dist, 1);
        b.bind("distances", dist, 0);
      },
      [=](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *resolve, &used, sizeof used, {groups(side), groups(side), 1});
      });
  return ok_status();
}

}  // namespace mrgi::gi
