// Light propagation volumes (runtime/src/gi/light_propagation.h) on lavapipe with validation:
// injection of VPLs and direct light as the paper's eq. 12-13 say, delta injection cancelling,
// propagation equal to the CPU's run of the same header (lpv_math.h), and stress values.
#include <glm/gtc/packing.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "gi/light_propagation.h"
#include "shared/lpv_math.h"
#include "vulkan/vk_test_util.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;
using mrgi::gpu::FrameTimings;
namespace sh = mrgi::shader;

constexpr uint32_t kN = 8;
constexpr float kCell = 0.25f;

struct Texel {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec4 flux;  // rgb reflected, a incident per unit colour
  bool virtual_surface = false;  // position w 2 (a virtual object's texel), else 1
};

struct Lpv {
  std::unique_ptr<gpu::FrameGraph> graph;
  std::optional<gi::LightPropagationVolume> lpv;
  gi::RsmImages rsm;
  gi::RsmImages blocker;  // the same texels 0.3 m nearer the light (a virtual object between)
  gpu::BufferHandle readback;

  uint32_t n = kN;
  std::vector<FrameTimings> timings;

  Lpv(gpu::Context& ctx, const std::vector<Texel>& texels, float damping = 1.0f, uint32_t cells = kN,
      bool one_step_a_dispatch = false)
      : n(cells) {
    gpu::FrameGraphSettings fs;
    fs.max_output_width = fs.max_output_height = 16;
    fs.frames_in_flight = 1;
    auto g = gpu::FrameGraph::create(ctx, fs);
    EXPECT_TRUE(g.ok());
    graph = std::move(*g);
    gi::LpvSettings s;
    s.name = "test lpv";
    s.resolution = n;
    s.negative_damping = damping;
    s.one_step_a_dispatch = one_step_a_dispatch;
    auto v = gi::LightPropagationVolume::create(*graph, s);
    EXPECT_TRUE(v.ok()) << v.error().message;
    lpv.emplace(std::move(*v));
    lpv->set_grid({glm::vec3(0.0f), kCell});
    const uint32_t w = uint32_t(texels.size());
    auto image = [&](const char* name, VkFormat f) {
      gpu::ImageDesc d;
      d.name = name;
      d.format = f;
      d.size_mode = gpu::SizeMode::Absolute;
      d.width = w;
      d.height = 1;
      return *graph->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    };
    rsm = {image("rsm position", VK_FORMAT_R32G32B32A32_SFLOAT), image("rsm normal", VK_FORMAT_R16G16B16A16_SFLOAT),
           image("rsm flux", VK_FORMAT_R32G32B32A32_SFLOAT), w, 1};
    blocker = rsm;
    blocker.position = image("blocker position", VK_FORMAT_R32G32B32A32_SFLOAT);
    std::vector<float> pos, flux, blocked;
    std::vector<uint16_t> nor;
    for (const Texel& t : texels) {
      blocked.insert(blocked.end(), {t.position.x, t.position.y + 0.3f, t.position.z, 1.0f});
      pos.insert(pos.end(), {t.position.x, t.position.y, t.position.z, t.virtual_surface ? 2.0f : 1.0f});
      for (float c : {t.normal.x, t.normal.y, t.normal.z, 0.0f}) nor.push_back(uint16_t(glm::packHalf1x16(c)));
      flux.insert(flux.end(), {t.flux.x, t.flux.y, t.flux.z, t.flux.w});
    }
    EXPECT_TRUE(graph->upload_image(rsm.position, pos.data(), pos.size() * 4).ok());
    EXPECT_TRUE(graph->upload_image(blocker.position, blocked.data(), blocked.size() * 4).ok());
    EXPECT_TRUE(graph->upload_image(rsm.normal, nor.data(), nor.size() * 2).ok());
    EXPECT_TRUE(graph->upload_image(rsm.flux, flux.data(), flux.size() * 4).ok());
    gpu::BufferDesc bd;
    bd.name = "lpv readback";
    bd.size = VkDeviceSize(n) * n * n * 16 * 3;
    bd.memory = gpu::MemoryUsage::Readback;
    readback = *graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  }

  // One frame: the injections `add` records, `steps` steps; returns the accumulated volume as
  // [channel][cell] SH.
  std::vector<std::vector<glm::vec4>> run(const std::function<void()>& add, uint32_t steps) {
    EXPECT_TRUE(graph->begin_frame().ok());
    lpv->add_clear(*graph);
    add();
    lpv->add_propagate(*graph, steps);
    graph->add_pass(
        "copy sum", gpu::PassKind::Transfer,
        [&](gpu::PassBuilder& b) {
          for (uint32_t c = 0; c < 3; ++c) b.read(lpv->accumulated(c), gpu::Access::TransferSrc);
          b.write(readback, gpu::Access::TransferDst);
        },
        [this](VkCommandBuffer cmd, gpu::PassContext& p) {
          for (uint32_t c = 0; c < 3; ++c) {
            VkBufferImageCopy r{};
            r.bufferOffset = VkDeviceSize(c) * n * n * n * 16;
            r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            r.imageExtent = {n, n, n};
            vkCmdCopyImageToBuffer(cmd, p.image(lpv->accumulated(c)), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   p.buffer(readback), 1, &r);
          }
        });
    graph->mark_output(readback);
    Status s = graph->compile();
    EXPECT_TRUE(s.ok()) << s.error().message;
    EXPECT_TRUE(graph->submit().ok());
    auto done = graph->flush();
    EXPECT_TRUE(done.ok());
    if (done.ok()) timings.insert(timings.end(), done->begin(), done->end());
    std::vector<std::vector<glm::vec4>> out(3, std::vector<glm::vec4>(size_t(n) * n * n));
    const auto* f = static_cast<const float*>(graph->mapped(readback, 0));
    for (uint32_t c = 0; c < 3; ++c) std::memcpy(out[c].data(), f + size_t(c) * n * n * n * 4, size_t(n) * n * n * 16);
    return out;
  }
  void inject(const char* label, gi::InjectKind kind, float sign, const gi::LpvLight& light = {}) {
    lpv->add_inject(*graph, label, rsm, light, kind, sign, kind == gi::InjectKind::Direct ? &blocker : nullptr);
  }
};

size_t cell(int x, int y, int z) { return size_t((z * int(kN) + y) * int(kN) + x); }

// The CPU's run of the same math: injected volume -> `steps` gathers, summed.
std::vector<glm::vec4> cpu_propagate(const std::vector<glm::vec4>& injected, uint32_t steps, float damping) {
  std::vector<glm::vec4> cur = injected, sum = injected, next(cur.size());
  for (uint32_t s = 0; s < steps; ++s) {
    for (int z = 0; z < int(kN); ++z)
      for (int y = 0; y < int(kN); ++y)
        for (int x = 0; x < int(kN); ++x) {
          glm::vec4 acc(0.0f);
          for (int k = 0; k < 6; ++k) {
            const glm::ivec3 q = glm::ivec3(x, y, z) + glm::ivec3(sh::lpv_axis(k));
            if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, glm::ivec3(int(kN)))))
              continue;
            acc += sh::lpv_gather_from(cur[cell(q.x, q.y, q.z)], cur[cell(x, y, z)], k, damping);
          }
          next[cell(x, y, z)] = acc;
        }
    cur.swap(next);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += cur[i];
  }
  return sum;
}

const gi::LpvLight kSunFromAbove{glm::vec3(0.0f, -1.0f, 0.0f), false, glm::vec3(1.0f)};

TEST_F(VulkanTest, LpvInjectsAVplHalfACellAlongItsNormal) {
  // A floor texel at (1.0, 0.5, 1.0) facing up, reflected flux (1, 2, 3) W: its VPL lands in the
  // cell of (1.0, 0.625, 1.0), (4, 2, 4), as P / pi max(0, n . w) (eq. 12); nothing elsewhere.
  Lpv t(ctx(), {{glm::vec3(1.0f, 0.5f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(1, 2, 3, 5)}});
  auto sum = t.run([&] { t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove); }, 0);
  for (uint32_t c = 0; c < 3; ++c) {
    const glm::vec4 want = sh::lpv_vpl_intensity(glm::vec3(0, 1, 0), float(c + 1));
    for (size_t i = 0; i < sum[c].size(); ++i) {
      const glm::vec4 expect = i == cell(4, 2, 4) ? want : glm::vec4(0.0f);
      for (int k = 0; k < 4; ++k) ASSERT_NEAR(sum[c][i][k], expect[k], 1e-6f) << "channel " << c << " cell " << i;
    }
  }
}

TEST_F(VulkanTest, LpvIndirectFromRealSurfacesLeavesVirtualTexelsOut) {
  // A real floor texel and a virtual one (position w 2) two cells apart: IndirectFromReal
  // injects the real one only, Indirect both.
  Lpv t(ctx(), {{glm::vec3(1.0f, 0.5f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(1, 1, 1, 1)},
                {glm::vec3(1.5f, 0.5f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(1, 1, 1, 1), true}});
  auto real = t.run([&] { t.inject("rho", gi::InjectKind::IndirectFromReal, 1.0f, kSunFromAbove); }, 0);
  auto all = t.run([&] { t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove); }, 0);
  const glm::vec4 vpl = sh::lpv_vpl_intensity(glm::vec3(0, 1, 0), 1.0f);
  for (uint32_t c = 0; c < 3; ++c) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(real[c][cell(4, 2, 4)][k], vpl[k], 1e-6f);
      EXPECT_NEAR(real[c][cell(6, 2, 4)][k], 0.0f, 1e-9f);
      EXPECT_NEAR(all[c][cell(6, 2, 4)][k], vpl[k], 1e-6f);
    }
  }
}

TEST_F(VulkanTest, LpvDeltaOfTwoEqualMapsIsZeroAndOfABlockedOneIsNegative) {
  Lpv t(ctx(), {{glm::vec3(1.0f, 0.5f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(1, 1, 1, 1)}});
  auto zero = t.run([&] {
    t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove);
    t.inject("mu", gi::InjectKind::Indirect, -1.0f, kSunFromAbove);
  }, 3);
  for (const auto& ch : zero)
    for (const glm::vec4& v : ch) ASSERT_EQ(v, glm::vec4(0.0f));
  // Only the map without the object sees the texel (the object blocks it in R^rho): antiradiance.
  auto blocked = t.run([&] { t.inject("mu", gi::InjectKind::Indirect, -1.0f, kSunFromAbove); }, 0);
  EXPECT_LT(sh::sh4_total_flux(blocked[0][cell(4, 2, 4)]), 0.0f);
}

TEST_F(VulkanTest, LpvDirectLightIsInjectedTowardsTheLightAlongItsTravel) {
  // Direct mode (Sec. 4.3.2): where the other map sees a nearer surface (the texel is blocked),
  // the light arriving at the texel (colour x incident W = 0.5 x 4),
  // as an emitter facing the way the light travels, half a cell towards the light (up): y 0.6 +
  // 0.125 = 0.725, cell (4, 2, 4).
  Lpv t(ctx(), {{glm::vec3(1.0f, 0.6f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(0, 0, 0, 4)}});
  gi::LpvLight sun = kSunFromAbove;
  sun.colour = glm::vec3(0.5f, 0.25f, 0.0f);
  auto sum = t.run([&] { t.inject("direct", gi::InjectKind::Direct, 1.0f, sun); }, 0);
  // Where the other map sees the same surface (nothing blocks the light), nothing is injected.
  auto unblocked = t.run([&] {
    t.lpv->add_inject(*t.graph, "unblocked", t.rsm, sun, gi::InjectKind::Direct, 1.0f, &t.rsm);
  }, 0);
  for (const glm::vec4& v : unblocked[0]) ASSERT_EQ(v, glm::vec4(0.0f));
  const glm::vec4 want = sh::lpv_vpl_intensity(glm::vec3(0, -1, 0), 2.0f);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(sum[0][cell(4, 2, 4)][k], want[k], 1e-6f);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(sum[1][cell(4, 2, 4)][k], want[k] * 0.5f, 1e-6f);
  EXPECT_EQ(sum[2][cell(4, 2, 4)], glm::vec4(0.0f));
  // A texel the light reaches from behind reflects no VPL.
  Lpv back(ctx(), {{glm::vec3(1.0f, 0.5f, 1.0f), glm::vec3(0, -1, 0), glm::vec4(1, 1, 1, 1)}});
  auto none = back.run([&] { back.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove); }, 0);
  for (const glm::vec4& v : none[0]) ASSERT_EQ(v, glm::vec4(0.0f));
}

TEST_F(VulkanTest, LpvPropagationMatchesTheCpuRunOfTheSameHeader) {
  // Two VPLs and a blocked one (negative), 6 steps, damping on: the GPU's accumulated volume is
  // the CPU's within float rounding.
  const std::vector<Texel> texels = {{glm::vec3(0.9f, 0.3f, 1.1f), glm::vec3(0, 1, 0), glm::vec4(1, 0.5f, 0.2f, 1)},
                                     {glm::vec3(1.6f, 1.0f, 0.4f), glm::normalize(glm::vec3(-1, 1, 0)), glm::vec4(0.3f, 1, 0.1f, 1)}};
  for (float damping : {0.0f, 1.0f}) {
    Lpv t(ctx(), texels, damping);
    auto injected = t.run([&] {
      t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove);
      t.inject("blocked", gi::InjectKind::Indirect, -0.5f, gi::LpvLight{glm::vec3(1, -1, 0), false, glm::vec3(1.0f)});
    }, 0);
    auto gpu = t.run([&] {
      t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove);
      t.inject("blocked", gi::InjectKind::Indirect, -0.5f, gi::LpvLight{glm::vec3(1, -1, 0), false, glm::vec3(1.0f)});
    }, 6);
    for (uint32_t c = 0; c < 3; ++c) {
      const std::vector<glm::vec4> cpu = cpu_propagate(injected[c], 6, damping);
      float scale = 0.0f;
      for (const glm::vec4& v : cpu) scale = std::max(scale, glm::length(v));
      ASSERT_GT(scale, 0.0f);
      for (size_t i = 0; i < cpu.size(); ++i)
        for (int k = 0; k < 4; ++k)
          ASSERT_NEAR(gpu[c][i][k], cpu[i][k], 1e-4f * scale) << "damping " << damping << " channel " << c << " cell " << i;
    }
  }
}

TEST_F(VulkanTest, LpvOneWorkgroupPropagationMatchesOneStepADispatch) {
  // The reduced volumes (<= 8^3) propagate every step in one workgroup (lpv_propagate_local.comp);
  // the same injection through both paths, 12 steps, damping on and off: the same volume to
  // float rounding (the CPU run above checks the math itself).
  const std::vector<Texel> texels = {{glm::vec3(0.9f, 0.3f, 1.1f), glm::vec3(0, 1, 0), glm::vec4(1, 0.5f, 0.2f, 1)},
                                     {glm::vec3(1.6f, 1.0f, 0.4f), glm::normalize(glm::vec3(-1, 1, 0)), glm::vec4(0.3f, 1, 0.1f, 1)}};
  for (float damping : {0.0f, 1.0f}) {
    std::vector<std::vector<glm::vec4>> out[2];
    for (int path = 0; path < 2; ++path) {
      Lpv t(ctx(), texels, damping, kN, path == 1);
      out[path] = t.run([&] {
        t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove);
        t.inject("blocked", gi::InjectKind::Indirect, -0.5f, gi::LpvLight{glm::vec3(1, -1, 0), false, glm::vec3(1.0f)});
      }, 12);
    }
    for (uint32_t c = 0; c < 3; ++c) {
      float scale = 0.0f;
      for (const glm::vec4& v : out[1][c]) scale = std::max(scale, glm::length(v));
      ASSERT_GT(scale, 0.0f);
      for (size_t i = 0; i < out[1][c].size(); ++i)
        for (int k = 0; k < 4; ++k)
          ASSERT_NEAR(out[0][c][i][k], out[1][c][i][k], 1e-5f * scale) << "damping " << damping << " channel " << c << " cell " << i;
    }
  }
}

TEST_F(VulkanTest, LpvStressValuesStayFiniteAndBounded) {
  // A lamp at 1e6, negative only, 64 steps (more than the volume is wide): every value finite,
  // and the accumulated flux never more than steps + 1 times what was injected (each step moves
  // light, never makes it: one step conserves an isotropic cell's flux exactly).
  Lpv t(ctx(), {{glm::vec3(1.0f, 1.0f, 1.0f), glm::vec3(0, 1, 0), glm::vec4(1e6f, 1e6f, 1e6f, 1e6f)}});
  auto sum = t.run([&] { t.inject("mu", gi::InjectKind::Indirect, -1.0f, kSunFromAbove); }, 64);
  double total = 0.0;
  for (const glm::vec4& v : sum[0]) {
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(v[k]));
    total += sh::sh4_total_flux(v);
  }
  EXPECT_LT(total, 0.0);
  EXPECT_LE(std::abs(total), 65.0 * 1e6 * 1.001);
  // Frames do not carry over: the same frame twice gives the same volume.
  auto again = t.run([&] { t.inject("mu", gi::InjectKind::Indirect, -1.0f, kSunFromAbove); }, 64);
  EXPECT_EQ(again[0], sum[0]);
}

TEST_F(VulkanTest, LpvRefusesBadSettingsByName) {
  auto g = gpu::FrameGraph::create(ctx(), gpu::FrameGraphSettings{});
  ASSERT_TRUE(g.ok());
  gi::LpvSettings s;
  s.resolution = 1;
  auto v = gi::LightPropagationVolume::create(**g, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("LpvSettings.resolution"), std::string::npos);
  s.resolution = 8;
  s.negative_damping = -1.0f;
  v = gi::LightPropagationVolume::create(**g, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("LpvSettings.negative_damping"), std::string::npos);
  s.negative_damping = 1.0f;
  v = gi::LightPropagationVolume::create(**g, s);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->set_cells(**g, 3).error().kind, ErrorKind::BadUsage);  // does not divide 8
  EXPECT_TRUE(v->set_cells(**g, 4).ok());
  EXPECT_EQ(v->cells(), 4u);
}

// Not a check (timings live in perf/): the propagation's cost on this device, for orientation.
TEST_F(VulkanTest, DISABLED_LpvPropagationTimes) {
  for (uint32_t n : {8u, 16u, 32u}) {
    Lpv t(ctx(), {{glm::vec3(0.1f * n, 0.05f * n, 0.1f * n), glm::vec3(0, 1, 0), glm::vec4(1, 1, 1, 1)}}, 1.0f, n);
    t.lpv->set_grid({glm::vec3(0.0f), 0.25f});
    ASSERT_TRUE(t.graph->set_profiling(true).ok());
    for (int f = 0; f < 4; ++f) t.run([&] { t.inject("rho", gi::InjectKind::Indirect, 1.0f, kSunFromAbove); }, n);
    for (const PassTiming& p : t.timings.back().passes) std::printf("lpv %u^3, %u steps: %-24s %.2f ms\n", n, n, p.name.c_str(), p.gpu_ms);
  }
}

}  // namespace
