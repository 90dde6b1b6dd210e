// The bounce light source (runtime/src/gi/vpl_bounce.h) on lavapipe with validation, on the rig
// of rsm_rig.h (a real floor y = 0 over x, z in [0.5, 1.5] seen from 1.5 m, albedo 0.5; a
// virtual 0.15 m box at (1, 0, 1), albedo 0.8). One source VPL above the box lights both; its ISMs
// are built from the same clouds. The bounce VPLs' flux must add up to the light the floor and
// the box reflect (integrated on the CPU), each kind apart; their flags must follow eq. 9 (the
// box's are virtual paths, the floor the box hides from the source is ir = 1), and an ir source
// must spawn nothing on the box. A glossy source (a specular lobe, shared/vpl_math.h
// vpl_intensity) must put the light of its lobe on the floor where the lobe points.
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/vpl.glsl"
#include "gi/ism.h"
#include "gi/rsm_rig.h"
#include "gi/vpl_bounce.h"
#include "shared/vpl_math.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kSlots = 256;
constexpr float kClamp = 0.01f;
const glm::vec3 kSource(1.15f, 0.45f, 1.1f);
const glm::vec3 kDown(0.0f, -1.0f, 0.0f);
const glm::vec3 kBoxLo(0.925f, 0.0f, 0.925f), kBoxHi(1.075f, 0.15f, 1.075f);

shader::Vpl diffuse_source(int flags) {
  return {glm::vec4(kSource, float(flags)), glm::vec4(kDown, 0.0f), glm::vec4(1.0f, 1.0f, 1.0f, 0.0f),
          glm::vec4(0.0f, 0.0f, 1.0f, -1.0f), glm::vec4(0.0f)};
}

std::vector<shader::Vpl> bounce(gpu::Context& ctx, const shader::Vpl& source_vpl, bool glossy = false) {
  test::RsmRig r(ctx);
  gi::IsmSettings is;
  is.max_vpls = 1;
  is.map_size = 64;
  auto ism = gi::ImperfectShadowMaps::create(*r.graph, *r.scene, r.real.position, r.real.normal, is);
  EXPECT_TRUE(ism.ok()) << ism.error().message;
  gi::VplBounceSettings bs;
  bs.max_slots = kSlots;
  bs.glossy = glossy;
  auto b = gi::VplBounce::create(*r.graph, *r.scene, {r.real.position, r.real.normal, r.real.albedo}, bs);
  EXPECT_TRUE(b.ok()) << b.error().message;
  gpu::BufferDesc vd{"source vpls", sizeof(shader::Vpl), gpu::MemoryUsage::Upload};
  const gpu::BufferHandle source = *r.graph->create_buffer(vd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  *static_cast<shader::Vpl*>(r.graph->mapped(source, 0)) = source_vpl;
  gpu::BufferDesc rd{"bounce readback", kSlots * sizeof(shader::Vpl), gpu::MemoryUsage::Readback};
  const gpu::BufferHandle readback = *r.graph->create_buffer(rd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  EXPECT_TRUE(r.graph->begin_frame().ok());
  gi::IsmFrame f;
  f.vpls = 1;
  f.map_size = 64;
  f.points_per_vpl = 2048;
  f.focal_px = glm::vec2(1.5f * float(test::kG - 1));  // 1 m across kG - 1 pixel steps at 1.5 m
  Status s = ism->add_build(*r.graph, source, f);
  EXPECT_TRUE(s.ok()) << s.error().message;
  gi::BounceFrame bf;
  bf.slots = kSlots;
  bf.source_vpls = 1;
  bf.source_ism_size = 64;
  bf.source_tiles_per_row = ism->tiles_per_row(1);
  bf.centre = glm::vec3(1.0f, 0.0f, 1.0f);
  bf.radius = 2.0f;  // the whole floor
  bf.clamp_m = kClamp;
  bf.focal_px = f.focal_px;
  s = b->add_bounce(*r.graph, source, ism->distances(), bf);
  EXPECT_TRUE(s.ok()) << s.error().message;
  const gpu::BufferHandle out = b->buffer();
  r.graph->add_pass(
      "copy", gpu::PassKind::Transfer,
      [&](gpu::PassBuilder& p) {
        p.read(out, gpu::Access::TransferSrc);
        p.write(readback, gpu::Access::TransferDst);
      },
      [&](VkCommandBuffer cmd, gpu::PassContext& p) {
        const VkBufferCopy c{0, 0, kSlots * sizeof(shader::Vpl)};
        vkCmdCopyBuffer(cmd, p.buffer(out), p.buffer(readback), 1, &c);
      });
  r.graph->mark_output(readback);
  s = r.graph->compile();
  EXPECT_TRUE(s.ok()) << s.error().message;
  EXPECT_TRUE(r.graph->submit().ok());
  EXPECT_TRUE(r.graph->flush().ok());
  const auto* v = static_cast<const shader::Vpl*>(r.graph->mapped(readback, 0));
  return std::vector<shader::Vpl>(v, v + kSlots);
}

// Reflected flux (W, one channel) of the surface the source lights: albedo x E over `n` x `n`
// cells of a rectangle (origin o, edges a, b, normal nrm), unoccluded (the floor's candidates are
// tested against the real casters only, and nothing real stands over it; a box face the source
// sees is not hidden by the convex box).
// `source`: the VPL (vpl_irradiance_rgb, channel x); `weighted_x`: the flux-weighted mean x.
double reflected(glm::vec3 o, glm::vec3 a, glm::vec3 b, glm::vec3 nrm, float albedo, const shader::Vpl& source,
                 double* weighted_x = nullptr) {
  constexpr int n = 200;
  double sum = 0.0, sum_x = 0.0;
  const double cell = double(glm::length(a)) * double(glm::length(b)) / double(n * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec3 p = o + a * ((float(i) + 0.5f) / n) + b * ((float(j) + 0.5f) / n);
      const double f = double(albedo) * double(shader::vpl_irradiance_rgb(p, nrm, glm::vec3(source.position), glm::vec3(source.normal),
                                                                          glm::vec3(source.flux), source.lobe, source.specular, kClamp).x) *
                       cell;
      sum += f;
      sum_x += f * double(p.x);
    }
  if (weighted_x) *weighted_x = sum > 0.0 ? sum_x / sum : 0.0;
  return sum;
}

// The angle (radians) between the direction from the source to p and the nearest direction to
// the box (0 when the box is in the way).
float angle_to_box(glm::vec3 p) {
  const glm::vec3 w = glm::normalize(p - kSource);
  float best = 10.0f;
  constexpr int n = 8;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        const glm::vec3 q = kBoxLo + (kBoxHi - kBoxLo) * glm::vec3(float(i), float(j), float(k)) / float(n);
        best = std::min(best, std::acos(std::clamp(glm::dot(w, glm::normalize(q - kSource)), -1.0f, 1.0f)));
      }
  return best;
}

bool on_box(glm::vec3 p) {
  return glm::all(glm::greaterThan(p, kBoxLo - 0.005f)) && glm::all(glm::lessThan(p, kBoxHi + 0.005f)) && p.y > 0.005f;
}

TEST_F(VulkanTest, BounceVplsCarryTheLightTheSurfacesReflect) {
  const shader::Vpl source = diffuse_source(MRGI_VPL_VALID | MRGI_VPL_REAL_PATH);
  const std::vector<shader::Vpl> v = bounce(ctx(), source);
  // The floor (its G-buffer spans 32 pixels of 1/31 m: 1.033 m a side) and the box's faces the
  // source sees from above and from its +x, +z side.
  const float side = float(test::kG) / float(test::kG - 1);
  const double floor_flux = reflected(glm::vec3(0.5f - 0.5f / float(test::kG - 1), 0.0f, 0.5f - 0.5f / float(test::kG - 1)),
                                      glm::vec3(side, 0, 0), glm::vec3(0, 0, side), glm::vec3(0, 1, 0), 0.5f, source);
  const float e = 0.15f;
  const double box_flux = reflected(glm::vec3(kBoxLo.x, kBoxHi.y, kBoxLo.z), glm::vec3(e, 0, 0), glm::vec3(0, 0, e), glm::vec3(0, 1, 0), 0.8f, source) +
                          reflected(glm::vec3(kBoxHi.x, 0, kBoxLo.z), glm::vec3(0, e, 0), glm::vec3(0, 0, e), glm::vec3(1, 0, 0), 0.8f, source) +
                          reflected(glm::vec3(kBoxLo.x, 0, kBoxHi.z), glm::vec3(e, 0, 0), glm::vec3(0, e, 0), glm::vec3(0, 0, 1), 0.8f, source);
  double real_sum = 0.0, virtual_sum = 0.0;
  int real_only = 0, virtual_paths = 0, empty = 0;
  for (const shader::Vpl& b : v) {
    const int flags = int(b.position.w);
    ASSERT_TRUE(std::isfinite(b.flux.x) && b.flux.x >= 0.0f);
    if ((flags & MRGI_VPL_VALID) == 0) {
      ++empty;
      continue;
    }
    const glm::vec3 p(b.position);
    if ((flags & MRGI_VPL_REAL_PATH) != 0) {
      EXPECT_NEAR(p.y, 0.0f, 1e-3f) << "a real-path bounce VPL lies on the floor";
      real_sum += b.flux.x;
      if ((flags & MRGI_VPL_REAL_ONLY) != 0) {
        ++real_only;
        // ir = 1: the box stands between the source and this floor point, as the ISM sees it:
        // splats (3 texels) and the pull-push (a 4 x 4 block) widen a silhouette by up to about
        // 6 texels of the 64^2 map, about 17 degrees.
        EXPECT_LT(angle_to_box(p), 0.3f) << "ir floor point off the box's shadow: " << p.x << ", " << p.z;
      }
    } else {
      EXPECT_TRUE(on_box(p)) << "a virtual-path bounce VPL lies on the box: " << p.x << ", " << p.y << ", " << p.z;
      EXPECT_EQ(flags & MRGI_VPL_REAL_ONLY, 0);
      ++virtual_paths;
      virtual_sum += b.flux.x;
    }
  }
  std::printf("bounce: floor %.4f W (expected %.4f), box %.4f W (expected %.4f); %d virtual, %d ir, %d empty of %u\n",
              real_sum, floor_flux, virtual_sum, box_flux, virtual_paths, real_only, empty, kSlots);
  EXPECT_EQ(empty, 0);
  EXPECT_GT(virtual_paths, 0);
  EXPECT_GT(real_only, 0) << "the floor under the box's shadow spawns ir VPLs";
  // Resampled candidates: each kind's expected sum is exact; 256 draws of 64 candidates (measured:
  // floor -1 %, box -7 % from 31 draws).
  EXPECT_NEAR(real_sum / floor_flux, 1.0, 0.1);
  EXPECT_NEAR(virtual_sum / box_flux, 1.0, 0.2);
}

TEST_F(VulkanTest, AnIrSourceSpawnsOnlyIrVplsOnRealSurfaces) {
  const std::vector<shader::Vpl> v = bounce(ctx(), diffuse_source(MRGI_VPL_VALID | MRGI_VPL_REAL_PATH | MRGI_VPL_REAL_ONLY));
  int valid = 0;
  for (const shader::Vpl& b : v) {
    const int flags = int(b.position.w);
    if ((flags & MRGI_VPL_VALID) == 0) continue;
    ++valid;
    EXPECT_EQ(flags, MRGI_VPL_VALID | MRGI_VPL_REAL_PATH | MRGI_VPL_REAL_ONLY) << "ir is copied to the next VPL";
    EXPECT_FALSE(on_box(glm::vec3(b.position))) << "an ir source's light ignores (and never lands on) the virtual objects";
  }
  EXPECT_GT(valid, int(kSlots) / 2);
}

TEST_F(VulkanTest, AGlossySourceLightsTheFloorWhereItsLobePoints) {
  // Only a specular lobe (no cosine emitter), its light arriving from down and to -x: the mirror
  // direction points down and to +x, away from the box.
  shader::Vpl source = diffuse_source(MRGI_VPL_VALID | MRGI_VPL_REAL_PATH);
  source.flux = glm::vec4(0.0f);
  source.lobe = glm::vec4(glm::normalize(glm::vec3(-0.6f, -1.0f, 0.0f)), 0.4f);
  source.specular = glm::vec4(1.0f, 1.0f, 1.0f, 1.0f);  // Phi_in F0 = Phi_in = 1 W: a white metal
  const std::vector<shader::Vpl> v = bounce(ctx(), source, true);
  const float side = float(test::kG) / float(test::kG - 1);
  double expected_x = 0.0;
  const double floor_flux = reflected(glm::vec3(0.5f - 0.5f / float(test::kG - 1), 0.0f, 0.5f - 0.5f / float(test::kG - 1)),
                                      glm::vec3(side, 0, 0), glm::vec3(0, 0, side), glm::vec3(0, 1, 0), 0.5f, source, &expected_x);
  double sum = 0.0, sum_x = 0.0;
  for (const shader::Vpl& b : v) {
    const int flags = int(b.position.w);
    ASSERT_TRUE(std::isfinite(b.flux.x) && b.flux.x >= 0.0f);
    if ((flags & MRGI_VPL_VALID) == 0 || (flags & MRGI_VPL_REAL_PATH) == 0) continue;
    EXPECT_LT(b.lobe.w, 0.0f) << "a VPL on a real surface is diffuse (the paper's real specular is 0)";
    sum += b.flux.x;
    sum_x += double(b.flux.x) * double(b.position.x);
  }
  const double mean_x = sum > 0.0 ? sum_x / sum : 0.0;
  std::printf("glossy bounce: floor %.4f W (expected %.4f), flux-weighted x %.3f (expected %.3f; the source at %.3f)\n", sum,
              floor_flux, mean_x, expected_x, double(kSource.x));
  EXPECT_GT(expected_x, double(kSource.x) + 0.05) << "the lobe points to +x (the test's premise)";
  EXPECT_NEAR(sum / floor_flux, 1.0, 0.15);
  EXPECT_NEAR(mean_x, expected_x, 0.05);
}

}  // namespace
