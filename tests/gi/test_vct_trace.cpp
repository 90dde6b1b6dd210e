// Cone tracing (shaders/gi/vct_trace.glsl, through shaders/probe/vct_trace_probe.comp) on
// lavapipe with validation, over volumes the shared blocks build from a lit wall
// (gi/voxelize.h, gi/voxel_light.h): a cone at the wall's front gathers its radiance and is
// stopped, its back hides and sends nothing, a cone beside it or away from it sees nothing.
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <vector>

#include "gi/voxel_light.h"
#include "gi/voxelize.h"
#include "volume_readback.h"
#include "vulkan/vk_test_util.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kN = 16;
constexpr float kVoxel = 0.1f;
constexpr float kWallZ = 0.85f;  // the wall's plane (voxel row 8), facing -z
const glm::vec3 kFlux(0.01f, 0.02f, 0.03f);  // per RSM texel, one texel per voxel of the wall

struct Vertex {
  glm::vec3 position, normal;
  glm::vec2 uv{0.0f};
};

struct Cone {
  glm::vec3 origin;
  float aperture;
  glm::vec3 dir;
  float max_distance;
};

struct TraceOptions {
  float step_scale = 1.0f;
  bool wall_is_object = false;  // the wall in the objects' volumes (delta = its light), else the scene's
  int flags = 1;                // VCT_LIGHT | VCT_WITHOUT
};
// Per cone: light_with + trans_with, light_without + trans_without.
struct Traced {
  glm::vec4 with, without;
};

std::vector<Traced> trace(gpu::Context& ctx, const std::vector<Cone>& cones, const TraceOptions& o = {}) {
  auto owned = test::make_block_graph(ctx);
  gpu::FrameGraph& graph = *owned;
  gi::VoxelizeSettings vs;
  vs.name = "wall visibility";
  vs.resolution = kN;
  auto vox = gi::Voxelizer::create(graph, vs);
  gi::VoxelLightSettings ls;
  ls.name = "wall light";
  ls.resolution = kN;
  auto light = gi::VoxelLight::create(graph, ls);
  vs.name = "empty visibility";
  auto empty_vox = gi::Voxelizer::create(graph, vs);
  ls.name = "empty light";
  auto empty_light = gi::VoxelLight::create(graph, ls);
  EXPECT_TRUE(vox.ok() && light.ok() && empty_vox.ok() && empty_light.ok());
  const gi::VoxelRegion region{glm::vec3(0.0f), kVoxel};
  vox->set_region(region);
  light->set_region(region);
  empty_vox->set_region(region);
  empty_light->set_region(region);

  // The wall as a mesh (two triangles over the whole region) and as a reflective shadow map
  // (a texel at each wall voxel's centre).
  const glm::vec3 n(0, 0, -1);
  const std::vector<Vertex> verts = {{{-0.1f, -0.1f, kWallZ}, n}, {{1.7f, -0.1f, kWallZ}, n},
                                     {{1.7f, 1.7f, kWallZ}, n},   {{-0.1f, 1.7f, kWallZ}, n}};
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
  auto storage = [&](const char* name, const void* data, size_t bytes) {
    gpu::BufferDesc bd;
    bd.name = name;
    bd.size = bytes;
    auto h = graph.create_buffer(bd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(ctx.upload_buffer(graph.gpu_buffer(*h, 0), data, bytes).ok());
    return *h;
  };
  const auto vb = storage("wall vertices", verts.data(), verts.size() * sizeof(Vertex));
  const auto ib = storage("wall indices", idx.data(), idx.size() * 4);
  auto image = [&](const char* name) {
    gpu::ImageDesc d;
    d.name = name;
    d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = kN;
    d.height = kN;
    return *graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  };
  gi::RsmImages rsm{image("rsm position"), {}, image("rsm flux"), kN, kN};
  std::vector<float> pos, flux;
  for (uint32_t y = 0; y < kN; ++y)
    for (uint32_t x = 0; x < kN; ++x) {
      pos.insert(pos.end(), {(float(x) + 0.5f) * kVoxel, (float(y) + 0.5f) * kVoxel, kWallZ, 1.0f});
      flux.insert(flux.end(), {kFlux.x, kFlux.y, kFlux.z, 0.0f});
    }
  EXPECT_TRUE(graph.upload_image(rsm.position, pos.data(), pos.size() * 4).ok());
  EXPECT_TRUE(graph.upload_image(rsm.flux, flux.data(), flux.size() * 4).ok());

  gpu::BufferDesc cd;
  cd.name = "cones";
  cd.size = cones.size() * 4 * sizeof(glm::vec4);
  cd.memory = gpu::MemoryUsage::Readback;
  auto cone_buffer = graph.create_buffer(cd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  EXPECT_TRUE(cone_buffer.ok());
  auto* io = static_cast<glm::vec4*>(graph.mapped(*cone_buffer, 0));
  for (size_t i = 0; i < cones.size(); ++i) {
    io[4 * i] = glm::vec4(cones[i].origin, cones[i].aperture);
    io[4 * i + 1] = glm::vec4(cones[i].dir, cones[i].max_distance);
    io[4 * i + 2] = io[4 * i + 3] = glm::vec4(-1.0f);
  }
  auto pipe = gpu::load_compute_pipeline(ctx, "probe/vct_trace_probe.comp", {});
  EXPECT_TRUE(pipe.ok()) << (pipe.ok() ? "" : pipe.error().message);

  EXPECT_TRUE(graph.begin_frame().ok());
  vox->add_clear(graph);
  vox->add_mesh(graph, "wall", vb, ib, {{0, 6, 0}});
  vox->add_resolve(graph);
  light->add_clear(graph);
  light->add_inject(graph, "wall", rsm, 1.0f);
  light->add_resolve(graph);
  empty_vox->add_clear(graph);
  empty_vox->add_resolve(graph);
  empty_light->add_clear(graph);
  empty_light->add_resolve(graph);
  const gpu::Pipeline* p = &**pipe;
  const VkSampler linear = ctx.samplers().linear_clamp;
  const gpu::ImageHandle wall_light = light->volume().image(0), wall_vis = vox->volume().image(0);
  const gpu::ImageHandle no_light = empty_light->volume().image(0), no_vis = empty_vox->volume().image(0);
  struct Push {
    glm::vec4 volume, sizes;
    glm::ivec4 flags;
  } push{glm::vec4(region.origin, kVoxel),
         glm::vec4(float(kN), float(vox->volume().used_levels() - 1), 0.1f, o.step_scale), glm::ivec4(o.flags, 0, 0, 0)};
  const bool object = o.wall_is_object;
  const uint32_t count = uint32_t(cones.size());
  const gpu::BufferHandle cb = *cone_buffer;
  graph.add_shader_pass(
      "trace cones", gpu::PassKind::Compute, *p,
      [&](gpu::ShaderPassBuilder& b) {
        b.bind_sampled("light_volume", wall_light, linear);
        b.bind_sampled("delta_volume", object ? wall_light : no_light, linear);
        b.bind_sampled("scene_visibility", object ? no_vis : wall_vis, linear);
        b.bind_sampled("object_visibility", object ? wall_vis : no_vis, linear);
        b.bind("Cones", cb);
      },
      [p, push, count](VkCommandBuffer cmd, gpu::PassContext&) { gpu::push_and_dispatch(cmd, *p, &push, sizeof push, {count, 1, 1}); });
  graph.mark_output(cb);
  Status s = graph.compile();
  EXPECT_TRUE(s.ok()) << s.error().message;
  EXPECT_TRUE(graph.submit().ok());
  EXPECT_TRUE(graph.flush().ok());
  std::vector<Traced> out;
  for (size_t i = 0; i < cones.size(); ++i) out.push_back({io[4 * i + 2], io[4 * i + 3]});
  return out;
}

// The step rule (vct_math.h vct_step): 20 cones of 0.3-1.2 rad at the lit one-voxel wall from
// 0.25-0.75 m, each should gather the wall's radiance (all of it: the wall covers every cone).
// The paper's touching footprints: 0.18 mean error, one cone at 0.25 (thin-wall aliasing); half
// those steps with the opacity corrected: 0.08, the default dvct traces with. Measured on
// lavapipe: 1/3 and 1/4 of the step were worse than 1/2 again (0.12, 0.11: where the samples
// fall still matters), 1/8 0.08 at 4x the samples of 1/2.
TEST_F(VulkanTest, VctHalfStepsGatherAThinWallMoreEvenlyThanThePapersStep) {
  const glm::vec3 radiance = kFlux / (std::numbers::pi_v<float> * kVoxel * kVoxel);
  const glm::vec3 mid(0.83f, 0.82f, 0.0f);
  std::vector<Cone> cones;
  for (float ap : {0.3f, 0.6f, 1.0f, 1.2f})
    for (float z : {0.1f, 0.2f, 0.3f, 0.45f, 0.6f}) cones.push_back({mid + glm::vec3(0, 0, z), ap, {0, 0, 1}, 3.0f});
  auto mean_error = [&](float step_scale) {
    TraceOptions o;
    o.step_scale = step_scale;
    const auto r = trace(ctx(), cones, o);
    double sum = 0.0;
    for (const Traced& t : r) {
      EXPECT_NEAR(t.with.x / radiance.x, 1.0f - t.with.w, 0.02f) << "light and occlusion go together";
      sum += std::abs(1.0 - t.with.x / radiance.x);
    }
    return sum / double(r.size());
  };
  const double paper = mean_error(1.0f), half = mean_error(0.5f);
  EXPECT_LT(half, 0.12) << "half steps";
  EXPECT_LT(half, 0.6 * paper) << "half steps against the paper's (" << paper << ")";
}

// The wall as a virtual object in front of an empty scene (delta volume = its light): with the
// object a cone sees its light and is stopped; without it, nothing and not stopped. A shadow
// cone (occlusion only) through it: stopped with, open without.
TEST_F(VulkanTest, VctWithAndWithoutTheObjectsSplitTheirLightAndOcclusion) {
  const glm::vec3 radiance = kFlux / (std::numbers::pi_v<float> * kVoxel * kVoxel);
  const glm::vec3 mid(0.8f, 0.8f, 0.0f);
  const std::vector<Cone> cones = {{mid + glm::vec3(0, 0, 0.2f), 0.3f, {0, 0, 1}, 3.0f},
                                   {mid + glm::vec3(0, 0, 0.3f), 1.0f, {0, 0, 1}, 3.0f}};
  TraceOptions o;
  o.step_scale = 0.5f;
  o.wall_is_object = true;
  o.flags = 3;  // VCT_LIGHT | VCT_WITHOUT
  for (const Traced& t : trace(ctx(), cones, o)) {
    EXPECT_GT(t.with.x, 0.75f * radiance.x);
    EXPECT_LT(t.with.w, 0.2f);
    EXPECT_NEAR(t.without.x, 0.0f, 0.01f * radiance.x) << "light minus delta: the scene sends nothing";
    EXPECT_NEAR(t.without.w, 1.0f, 1e-4f) << "the scene's visibility holds nothing";
  }
  o.flags = 2;  // a shadow cone: occlusion only
  for (const Traced& t : trace(ctx(), cones, o)) {
    EXPECT_EQ(glm::vec3(t.with), glm::vec3(0.0f)) << "no light read";
    EXPECT_LT(t.with.w, 0.2f);
    EXPECT_NEAR(t.without.w, 1.0f, 1e-4f);
  }
}

TEST_F(VulkanTest, VctConesSeeTheWallsRadianceFromItsFrontAndNothingElsewhere) {
  const glm::vec3 radiance = kFlux / (std::numbers::pi_v<float> * kVoxel * kVoxel);
  const glm::vec3 mid(0.8f, 0.8f, 0.0f);
  const std::vector<Cone> cones = {
      {mid + glm::vec3(0, 0, 0.2f), 0.3f, {0, 0, 1}, 3.0f},    // 0: at the front, narrow
      {mid + glm::vec3(0, 0, 0.3f), 1.2f, {0, 0, 1}, 3.0f},    // 1: at the front, wide (diffuse)
      {mid + glm::vec3(0, 0, 0.2f), 0.3f, {0, 0, -1}, 3.0f},   // 2: away from it
      {mid + glm::vec3(0, 0, 1.4f), 0.3f, {0, 0, -1}, 3.0f},   // 3: at its back
      {glm::vec3(0.05f, 0.8f, 0.4f), 0.3f, {1, 0, 0}, 3.0f},   // 4: beside it, parallel
      {mid + glm::vec3(0, 0, 0.2f), 0.3f, {0, 0, 1}, 0.3f},    // 5: stops short of it
  };
  std::vector<glm::vec4> r;  // light, occlusion
  for (const Traced& t : trace(ctx(), cones)) r.push_back(glm::vec4(glm::vec3(t.with), 1.0f - t.with.w));
  ASSERT_EQ(r.size(), cones.size());
  // A narrow cone reads the one-voxel wall at fine levels: its radiance, and it is stopped.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r[0][c], radiance[c], 0.15f * radiance[c]) << "narrow cone, channel " << c;
  EXPECT_GT(r[0].w, 0.95f);
  // A wide cone (1.2 rad) steps by its footprint (Sec. 3.1: footprints touch, a factor 5.3 a
  // step here) and meets the wall once, at level 2-3, interpolated with the empty space before
  // it: it gathers about half of the wall's light and occlusion (0.57 on lavapipe). A known
  // limit of the paper's step rule on thin surfaces; dvct's diffuse cones are measured against
  // the path-traced reference before a denser step is chosen. Bounds: not nothing, not more.
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(r[1][c], 0.4f * radiance[c]) << "wide cone, channel " << c;
    EXPECT_LT(r[1][c], 1.05f * radiance[c]) << "wide cone, channel " << c;
    EXPECT_NEAR(r[1][c] / radiance[c], r[1].w, 0.05f) << "light and occlusion go together";
  }
  EXPECT_EQ(r[2], glm::vec4(0.0f)) << "away: nothing";
  EXPECT_GT(r[3].w, 0.75f) << "the back occludes (0.81: the same stepping, from the other side)";
  EXPECT_LT(r[3].x, 0.02f * radiance.x) << "the back sends nothing";
  EXPECT_LT(r[4].w, 0.05f) << "a cone parallel to the wall is not stopped by it";
  EXPECT_LT(r[5].w, 0.05f) << "a cone that ends before the wall";
  for (const glm::vec4& v : r)
    for (int k = 0; k < 4; ++k) EXPECT_TRUE(std::isfinite(v[k]));
}

}  // namespace
