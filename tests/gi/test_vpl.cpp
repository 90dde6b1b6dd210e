// VPLs from a map pair (runtime/src/gi/vpl.h) on lavapipe with validation, on the rig of
// rsm_rig.h (a grey floor, a white virtual box on it, a sun from above): the VPLs' flux sums to
// the maps' reflected flux, each map's share of the slots follows the texels it covers, and the
// flags are the DIR paper's (Sec. 3.3): box-top VPLs virtual, floor VPLs real, floor VPLs under
// the box real-only.
#include <cmath>
#include <vector>

#include "common/vpl.glsl"
#include "gi/rsm_rig.h"
#include "gi/vpl.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;
using test::kCentre;
using test::kMap;
using test::kRadius;

struct Sampled {
  std::vector<shader::Vpl> vpls;
  std::vector<glm::vec4> rho_position, rho_flux, mu_position, mu_flux;
};

Sampled sample(gpu::Context& ctx, uint32_t count, bool real_lamp, bool glossy = false) {
  test::RsmRig r(ctx);
  gi::VplSettings vs;
  vs.glossy = glossy;
  vs.max_vpls = count + 8;
  vs.map_size = kMap;
  auto sampler = gi::VplSampler::create(*r.graph, vs);
  EXPECT_TRUE(sampler.ok()) << sampler.error().message;
  auto view = gi::rsm_view(test::sun(), kCentre, kRadius, kMap);
  EXPECT_TRUE(view.ok());
  gpu::BufferDesc bd{"vpl readback", VkDeviceSize(vs.max_vpls) * sizeof(shader::Vpl), gpu::MemoryUsage::Readback};
  const gpu::BufferHandle vpl_readback = *r.graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  EXPECT_TRUE(r.graph->begin_frame().ok());
  r.rsm->add_grid(*r.graph, 1);
  r.rsm->add_pair(*r.graph, "0", *view, kMap);
  const gi::RsmImages rho = r.rsm->images(gi::RsmMap::WithVirtual, kMap), mu = r.rsm->images(gi::RsmMap::RealOnly, kMap);
  sampler->add_clear(*r.graph);
  Status s = sampler->add_sample(*r.graph, "0", rho, mu, real_lamp, {view->light, glm::vec3(view->colour)}, 4, count);  // slots 4.. : the others stay empty
  EXPECT_TRUE(s.ok()) << s.error().message;
  const gpu::BufferHandle vpls = sampler->buffer();
  const gpu::ImageHandle maps[4] = {rho.position, rho.flux, mu.position, mu.flux};
  r.graph->add_pass(
      "copy", gpu::PassKind::Transfer,
      [&](gpu::PassBuilder& b) {
        for (gpu::ImageHandle h : maps) b.read(h, gpu::Access::TransferSrc);
        b.read(vpls, gpu::Access::TransferSrc);
        b.write(r.readback, gpu::Access::TransferDst);
        b.write(vpl_readback, gpu::Access::TransferDst);
      },
      [&](VkCommandBuffer cmd, gpu::PassContext& p) {
        for (int i = 0; i < 4; ++i) {
          VkBufferImageCopy c{};
          c.bufferOffset = VkDeviceSize(i) * kMap * kMap * 16;
          c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
          c.imageExtent = {kMap, kMap, 1};
          vkCmdCopyImageToBuffer(cmd, p.image(maps[i]), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(r.readback), 1, &c);
        }
        const VkBufferCopy bc{0, 0, VkDeviceSize(vs.max_vpls) * sizeof(shader::Vpl)};
        vkCmdCopyBuffer(cmd, p.buffer(vpls), p.buffer(vpl_readback), 1, &bc);
      });
  r.graph->mark_output(r.readback);
  r.graph->mark_output(vpl_readback);
  s = r.graph->compile();
  EXPECT_TRUE(s.ok()) << s.error().message;
  EXPECT_TRUE(r.graph->submit().ok());
  EXPECT_TRUE(r.graph->flush().ok());
  Sampled out;
  const auto* v = static_cast<const shader::Vpl*>(r.graph->mapped(vpl_readback, 0));
  out.vpls.assign(v, v + vs.max_vpls);
  const auto* f = static_cast<const glm::vec4*>(r.graph->mapped(r.readback, 0));
  const size_t n = size_t(kMap) * kMap;
  out.rho_position.assign(f, f + n);
  out.rho_flux.assign(f + n, f + 2 * n);
  out.mu_position.assign(f + 2 * n, f + 3 * n);
  out.mu_flux.assign(f + 3 * n, f + 4 * n);
  return out;
}

int flags_of(const shader::Vpl& v) { return int(v.position.w); }

TEST_F(VulkanTest, VplsFromARealLampsPairCarryTheMapsFluxWithThePaperFlags) {
  const uint32_t count = 256;
  const Sampled s = sample(ctx(), count, true);
  // What the maps hold: R^mu's flux (the real map) and R^rho's virtual texels' (the virtual map).
  double real_flux = 0.0, virtual_flux = 0.0;
  int real_texels = 0, virtual_texels = 0, hidden_texels = 0;
  for (size_t i = 0; i < s.mu_position.size(); ++i) {
    if (s.mu_position[i].w > 0.5f) real_flux += s.mu_flux[i].g, ++real_texels;
    if (s.rho_position[i].w > 1.5f) {
      virtual_flux += s.rho_flux[i].g, ++virtual_texels;
      if (s.mu_position[i].w > 0.5f) ++hidden_texels;
    }
  }
  ASSERT_GT(virtual_texels, 50);
  // Each VPL carries its texel's flux over the probability of drawing it: the map's share of the
  // slots (covered texels) times the texel's share of the map's luminance (grey maps: its share
  // of the flux), times the slot count; so every VPL of a map carries the same flux here.
  const double covered = double(real_texels + virtual_texels);
  const double want_real = real_flux / (real_texels / covered * count);
  const double want_virtual = virtual_flux / (virtual_texels / covered * count);
  int n_real = 0, n_virtual = 0, n_real_only = 0;
  for (size_t i = 0; i < s.vpls.size(); ++i) {
    const shader::Vpl& v = s.vpls[i];
    const int flags = flags_of(v);
    if (i < 4 || i >= 4 + count) {  // slots outside the range: emptied by the clear
      EXPECT_EQ(flags, 0);
      continue;
    }
    ASSERT_TRUE(flags & MRGI_VPL_VALID) << "slot " << i;
    ASSERT_TRUE(std::isfinite(v.flux.r) && std::isfinite(v.flux.g) && std::isfinite(v.flux.b));
    EXPECT_NEAR(glm::length(glm::vec3(v.normal)), 1.0f, 1e-3f);
    EXPECT_GT(v.normal.y, 0.99f);  // floor and box top face the sun
    if (flags & MRGI_VPL_REAL_PATH) {
      ++n_real;
      EXPECT_NEAR(v.flux.g, want_real, 1e-3 * want_real);
      EXPECT_NEAR(v.position.y, 0.0f, 1e-3f);  // on the floor
      if (flags & MRGI_VPL_REAL_ONLY) {
        ++n_real_only;
        // Under the box (x, z within its 0.15 m footprint around (1, 1)).
        EXPECT_LT(std::abs(v.position.x - 1.0f), 0.09f);
        EXPECT_LT(std::abs(v.position.z - 1.0f), 0.09f);
      }
    } else {
      ++n_virtual;
      EXPECT_NEAR(v.flux.g, want_virtual, 1e-3 * want_virtual);
      EXPECT_FALSE(flags & MRGI_VPL_REAL_ONLY);
      EXPECT_NEAR(v.position.y, 0.15f, 2e-3f);  // on the box top
    }
  }
  // Slots split by covered texels (Halton: within a couple of slots).
  const double share = double(virtual_texels) / double(real_texels + virtual_texels);
  EXPECT_NEAR(double(n_virtual), share * count, 2.0);
  // The real map's VPLs under the box: in proportion to the texels it hides.
  EXPECT_NEAR(double(n_real_only), double(n_real) * hidden_texels / real_texels, 3.0);
}

TEST_F(VulkanTest, VplsOfAVirtualLampAreAllOffTheRealPath) {
  const Sampled s = sample(ctx(), 64, false);
  double rho_flux = 0.0, vpl_flux = 0.0;
  for (size_t i = 0; i < s.rho_position.size(); ++i)
    if (s.rho_position[i].w > 0.5f) rho_flux += s.rho_flux[i].g;
  for (size_t i = 4; i < 4 + 64; ++i) {
    EXPECT_EQ(flags_of(s.vpls[i]), MRGI_VPL_VALID);  // neither real path nor real-only
    vpl_flux += s.vpls[i].flux.g;
  }
  EXPECT_NEAR(vpl_flux, rho_flux, 1e-3 * rho_flux);  // one map, all casters: R^rho's flux
}

TEST_F(VulkanTest, VplSettingsOutOfRangeAreRefusedNamingTheField) {
  test::RsmRig r(ctx());
  gi::VplSettings s;
  s.map_size = 100;
  auto v = gi::VplSampler::create(*r.graph, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("VplSettings.map_size"), std::string::npos);
  s.map_size = 64;
  s.max_vpls = 0;
  v = gi::VplSampler::create(*r.graph, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("VplSettings.max_vpls"), std::string::npos);
}

TEST_F(VulkanTest, GlossyVplsSplitAVirtualTexelsLightIntoACosineEmitterAndALobe) {
  // The rig's box is white_box.gltf: base 0.8, metallic 0, roughness 1 (F0 0.04); the sun shines
  // straight down. Every VPL carries the same share of the flux as without lobes
  // (VplsFromARealLampsPair...): the box's split by shared/vpl_math.h vpl_glossy_split, the
  // floor's (real) unchanged and diffuse.
  const uint32_t count = 256;
  const Sampled plain = sample(ctx(), count, true, false);
  const Sampled glossy = sample(ctx(), count, true, true);
  int n_virtual = 0;
  for (size_t i = 4; i < 4 + count; ++i) {
    const shader::Vpl& a = plain.vpls[i];
    const shader::Vpl& b = glossy.vpls[i];
    ASSERT_EQ(flags_of(a), flags_of(b)) << "slot " << i;
    if (flags_of(b) & MRGI_VPL_REAL_PATH) {
      EXPECT_LT(b.lobe.w, 0.0f) << "real surfaces are diffuse";
      EXPECT_NEAR(b.flux.g, a.flux.g, 1e-5f * a.flux.g);
      EXPECT_EQ(b.specular.g, 0.0f);
      continue;
    }
    ++n_virtual;
    const float incident = a.flux.g / 0.8f;  // Phi_in: the plain VPL reflects base x Phi_in
    EXPECT_NEAR(b.lobe.w, 1.0f, 1e-6f) << "the material's roughness";
    EXPECT_NEAR(b.lobe.y, 1.0f, 1e-4f) << "the light came from straight above";
    EXPECT_NEAR(b.flux.g, 0.8f * 0.96f * incident, 1e-4f * incident);
    EXPECT_NEAR(b.specular.g, 0.04f * incident, 1e-4f * incident);
    EXPECT_NEAR(b.specular.w, incident, 1e-3f * incident) << "Phi_in's luminance (a white sun)";
  }
  EXPECT_GT(n_virtual, 3);  // 7: the box covers 3 % of the map
}

}  // namespace
