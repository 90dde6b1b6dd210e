// Reflective shadow maps (runtime/src/gi/rsm.h) on lavapipe with validation: a real floor from a
// synthetic G-buffer and a virtual box (perf/suite/assets/white_box.gltf), a sun from above. The
// maps hold what rsm.frag says (position, normal, reflected and incident flux per texel), and
// the delta of the two maps injected into a volume is the box top's extra light.
#include <cmath>
#include <cstring>
#include <vector>

#include "gi/rsm_rig.h"
#include "shared/lpv_math.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;
namespace sh = mrgi::shader;

using test::kCentre;
using test::kG;
using test::kMap;
using test::kRadius;
using test::sun;
using Rig = test::RsmRig;

TEST_F(VulkanTest, RsmPairHoldsFloorAndBoxAndTheirDeltaIsTheBoxTop) {
  Rig r(ctx());
  auto view = gi::rsm_view(sun(), kCentre, kRadius, kMap);
  ASSERT_TRUE(view.ok()) << view.error().message;
  ASSERT_TRUE(r.graph->begin_frame().ok());
  r.rsm->add_grid(*r.graph, 1);
  r.rsm->add_pair(*r.graph, "0", *view, kMap);
  const gi::RsmImages rho = r.rsm->images(gi::RsmMap::WithVirtual, kMap), mu = r.rsm->images(gi::RsmMap::RealOnly, kMap);
  // The delta from the texels where the maps differ only (the rest cancel: the next check).
  r.lpv->add_clear(*r.graph);
  r.lpv->add_inject(*r.graph, "delta", rho, view->lpv, gi::InjectKind::Indirect, 1.0f, &mu);
  r.lpv->add_propagate(*r.graph, 0);
  const gpu::ImageHandle copies[5] = {rho.position, rho.flux, mu.position, mu.flux, r.lpv->accumulated(0)};
  r.graph->add_pass(
      "copy maps", gpu::PassKind::Transfer,
      [&](gpu::PassBuilder& b) {
        for (const gpu::ImageHandle h : copies) b.read(h, gpu::Access::TransferSrc);
        b.write(r.readback, gpu::Access::TransferDst);
      },
      [&, copies](VkCommandBuffer cmd, gpu::PassContext& p) {
        for (int i = 0; i < 5; ++i) {
          VkBufferImageCopy c{};
          c.bufferOffset = VkDeviceSize(i) * kMap * kMap * 16;
          c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
          c.imageExtent = i < 4 ? VkExtent3D{kMap, kMap, 1} : VkExtent3D{8, 8, 8};
          vkCmdCopyImageToBuffer(cmd, p.image(copies[i]), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(r.readback), 1, &c);
        }
      });
  r.graph->mark_output(r.readback);
  Status s = r.graph->compile();
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE(r.graph->submit().ok());
  ASSERT_TRUE(r.graph->flush().ok());
  const auto* f = static_cast<const glm::vec4*>(r.graph->mapped(r.readback, 0));
  auto at = [&](int map, uint32_t x, uint32_t y) { return f[size_t(map) * kMap * kMap + y * kMap + x]; };
  const float area = std::pow(2.0f * kRadius / float(kMap), 2.0f);
  // The centre texel: the box top in R^rho (0.15 m up, albedo 0.8), the floor in R^mu (0.5).
  const glm::vec4 rho_p = at(0, kMap / 2, kMap / 2), mu_p = at(2, kMap / 2, kMap / 2);
  EXPECT_EQ(rho_p.w, 2.0f);  // a virtual surface
  EXPECT_EQ(mu_p.w, 1.0f);   // a real one
  EXPECT_NEAR(rho_p.y, 0.15f, 1e-3f);
  EXPECT_NEAR(mu_p.y, 0.0f, 1e-3f);
  const glm::vec4 rho_f = at(1, kMap / 2, kMap / 2), mu_f = at(3, kMap / 2, kMap / 2);
  EXPECT_NEAR(rho_f.w, area, 1e-3f * area);               // incident W per unit colour
  EXPECT_NEAR(rho_f.x, 0.8f * 2.0f * area, 1e-3f * area);  // reflected
  EXPECT_NEAR(mu_f.x, 0.5f * 2.0f * area, 1e-3f * area);
  // Box-top texels: where the maps differ. Their count is the box's top in texels, about
  // (0.15 m / texel)^2, and the delta volume holds their extra reflected flux, (0.8 - 0.5) x 2 W/m^2
  // x their area, in total.
  // R^rho is R^mu's copy with the box drawn over it: off the box both maps hold the same
  // position and flux bit for bit.
  int box = 0, valid_mu = 0, off_box_differing = 0;
  for (uint32_t y = 0; y < kMap; ++y)
    for (uint32_t x = 0; x < kMap; ++x) {
      const bool on_box = at(0, x, y).y > 0.1f;
      box += on_box ? 1 : 0;
      valid_mu += at(2, x, y).w > 0.5f ? 1 : 0;
      if (!on_box && (at(0, x, y) != at(2, x, y) || at(1, x, y) != at(3, x, y))) ++off_box_differing;
    }
  EXPECT_EQ(off_box_differing, 0);
  const float box_texels = std::pow(0.15f / (2.0f * kRadius / float(kMap)), 2.0f);
  EXPECT_NEAR(float(box), box_texels, 0.15f * box_texels);
  EXPECT_GT(valid_mu, int(0.95 * kMap * kMap));  // the floor fills the map
  double delta = 0.0;
  const glm::vec4* vol = f + size_t(4) * kMap * kMap;
  for (int i = 0; i < 8 * 8 * 8; ++i) delta += sh::sh4_total_flux(vol[i]);
  const double want = (0.8 - 0.5) * 2.0 * area * box;
  EXPECT_NEAR(delta, want, 0.02 * want);
}

TEST(RsmView, RefusesAPointLampInsideTheVolume) {
  LightDesc lamp;
  lamp.type = LightType::Point;
  lamp.position = kCentre + glm::vec3(0.1f, 0.0f, 0.0f);
  auto v = gi::rsm_view(lamp, kCentre, kRadius, kMap);
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(v.error().message.find("inside its sphere"), std::string::npos);
  lamp.position = kCentre + glm::vec3(0.0f, 2.0f, 0.0f);
  v = gi::rsm_view(lamp, kCentre, kRadius, kMap);
  ASSERT_TRUE(v.ok());
  EXPECT_TRUE(v->lpv.positional);
  EXPECT_GT(v->light.w, 0.0f);  // the texel's solid angle at the centre
}

}  // namespace
