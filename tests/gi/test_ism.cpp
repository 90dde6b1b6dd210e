// Imperfect shadow maps (runtime/src/gi/ism.h) on lavapipe with validation, on the rig of
// rsm_rig.h (a real floor y = 0 over x, z in [0.5, 1.5] seen from 1.5 m, a virtual 0.15 m box at
// (1, 0, 1)): two VPLs looking down, each map holds the distance to the floor (real) and to the
// box (virtual) in the directions they lie, nothing where no surface is, and each VPL's tile only
// its own points.
#include <cmath>
#include <vector>

#include "common/vpl.glsl"
#include "gi/ism.h"
#include "gi/rsm_rig.h"
#include "shared/vpl_math.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kSide = 32;  // texels per VPL map

struct Maps {
  std::vector<glm::vec2> texels;  // the atlas, level 0 (x real, y virtual)
  uint32_t row = 0;
  glm::vec2 at(int vpl, glm::vec3 from, glm::vec3 normal, glm::vec3 to) const {
    const glm::vec3 w = glm::normalize(to - from);
    const glm::vec2 uv = shader::paraboloid_uv(w, normal);
    const glm::ivec2 t = glm::clamp(glm::ivec2(glm::floor((uv * 0.5f + 0.5f) * float(kSide))), glm::ivec2(0), glm::ivec2(kSide - 1));
    const glm::ivec2 origin = glm::ivec2(vpl % int(row), vpl / int(row)) * int(kSide);
    return texels[size_t(origin.y + t.y) * (row * kSide) + size_t(origin.x + t.x)];
  }
};

const glm::vec3 kDown(0.0f, -1.0f, 0.0f);
const glm::vec3 kVpl0(1.0f, 0.5f, 1.0f), kVpl1(0.7f, 0.3f, 0.7f);
const glm::vec3 kOrthoCentre(1.0f, 0.1f, 1.0f);
constexpr float kOrthoHalf = 0.3f;

Maps build(gpu::Context& ctx, uint32_t points_per_vpl) {
  test::RsmRig r(ctx);
  gi::IsmSettings is;
  is.max_vpls = 4;
  is.map_size = kSide;
  auto ism = gi::ImperfectShadowMaps::create(*r.graph, *r.scene, r.real.position, r.real.normal, is);
  EXPECT_TRUE(ism.ok()) << ism.error().message;
  gpu::BufferDesc vd{"test vpls", 4 * sizeof(shader::Vpl), gpu::MemoryUsage::Upload};
  const gpu::BufferHandle vpls = *r.graph->create_buffer(vd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* v = static_cast<shader::Vpl*>(r.graph->mapped(vpls, 0));
  v[0] = {glm::vec4(kVpl0, float(MRGI_VPL_VALID)), glm::vec4(kDown, 0.0f), glm::vec4(1.0f)};
  v[1] = {glm::vec4(kVpl1, float(MRGI_VPL_VALID)), glm::vec4(kDown, 0.0f), glm::vec4(1.0f)};
  v[2] = {glm::vec4(0.0f), glm::vec4(kDown, 0.0f), glm::vec4(0.0f)};  // empty slot: splats nothing
  // A directional VPL (an environment region) straight above: its map is orthographic over the
  // 0.6 m square around (1, 0.1, 1).
  v[3] = {glm::vec4(kOrthoCentre, float(MRGI_VPL_VALID | MRGI_VPL_DIRECTIONAL)), glm::vec4(0.0f, 1.0f, 0.0f, kOrthoHalf),
          glm::vec4(1.0f)};
  Maps out;
  out.row = ism->tiles_per_row(4);
  const uint32_t atlas = out.row * kSide;
  gpu::BufferDesc bd{"ism readback", VkDeviceSize(atlas) * atlas * 8, gpu::MemoryUsage::Readback};
  const gpu::BufferHandle readback = *r.graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  EXPECT_TRUE(r.graph->begin_frame().ok());
  gi::IsmFrame f;
  f.vpls = 4;
  f.map_size = kSide;
  f.points_per_vpl = points_per_vpl;
  f.focal_px = glm::vec2(1.5f * float(test::kG - 1));  // 1 m across kG - 1 pixel steps at 1.5 m
  Status s = ism->add_build(*r.graph, vpls, f);
  EXPECT_TRUE(s.ok()) << s.error().message;
  const gpu::ImageHandle dist = ism->distances();
  r.graph->add_pass(
      "copy", gpu::PassKind::Transfer,
      [&](gpu::PassBuilder& b) {
        b.read(dist, gpu::Access::TransferSrc, 0);
        b.write(readback, gpu::Access::TransferDst);
      },
      [&](VkCommandBuffer cmd, gpu::PassContext& p) {
        VkBufferImageCopy c{};
        c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        c.imageExtent = {atlas, atlas, 1};
        vkCmdCopyImageToBuffer(cmd, p.image(dist), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(readback), 1, &c);
      });
  r.graph->mark_output(readback);
  s = r.graph->compile();
  EXPECT_TRUE(s.ok()) << s.error().message;
  EXPECT_TRUE(r.graph->submit().ok());
  EXPECT_TRUE(r.graph->flush().ok());
  const auto* t = static_cast<const glm::vec2*>(r.graph->mapped(readback, 0));
  out.texels.assign(t, t + size_t(atlas) * atlas);
  return out;
}

TEST_F(VulkanTest, IsmsHoldTheDistanceToTheRealAndTheVirtualSurfaces) {
  const Maps m = build(ctx(), 1024);
  // VPL 0 straight above the box: the floor 0.5 m below (real), the box top 0.35 m (virtual).
  const glm::vec2 below = m.at(0, kVpl0, kDown, glm::vec3(1.0f, 0.0f, 1.0f));
  EXPECT_NEAR(below.x, 0.5f, 0.02f);
  EXPECT_NEAR(below.y, 0.35f, 0.02f);
  // Off the box, towards (0.6, 0, 1): the floor at |(-0.4, -0.5, 0)|; no virtual surface.
  const glm::vec2 off = m.at(0, kVpl0, kDown, glm::vec3(0.6f, 0.0f, 1.0f));
  EXPECT_NEAR(off.x, std::sqrt(0.16f + 0.25f), 0.03f);
  EXPECT_GT(off.y, 1e29f);
  // Towards the horizon beyond the floor's edge: nothing in either map.
  const glm::vec2 far = m.at(0, kVpl0, kDown, kVpl0 + glm::vec3(3.0f, -0.3f, 0.0f));
  EXPECT_GT(far.x, 1e29f);
  EXPECT_GT(far.y, 1e29f);
  // VPL 1 has its own tile: towards the box's top corner nearest to it.
  const glm::vec3 corner(0.93f, 0.15f, 0.93f);
  const glm::vec2 c = m.at(1, kVpl1, kDown, corner);
  EXPECT_NEAR(c.y, glm::length(corner - kVpl1), 0.04f);
  EXPECT_NEAR(m.at(1, kVpl1, kDown, glm::vec3(0.7f, 0.0f, 0.7f)).x, 0.3f, 0.02f);
  // The empty slot's tile stays empty.
  const int origin_x = 2 % int(m.row) * int(kSide), origin_y = 2 / int(m.row) * int(kSide);
  int filled = 0;
  for (uint32_t y = 0; y < kSide; ++y)
    for (uint32_t x = 0; x < kSide; ++x) {
      const glm::vec2 d = m.texels[size_t(origin_y + y) * (m.row * kSide) + size_t(origin_x + x)];
      filled += (d.x < 1e29f || d.y < 1e29f) ? 1 : 0;
    }
  EXPECT_EQ(filled, 0);
}

TEST_F(VulkanTest, ADirectionalVplsMapIsOrthographicAlongItsLight) {
  const Maps m = build(ctx(), 1024);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  auto texel = [&](glm::vec3 p, float& depth) {
    float d = 0.0f;
    const glm::vec3 x = p - kOrthoCentre;
    const glm::vec2 uv = glm::vec2(glm::dot(x, shader::frame_tangent(up)), glm::dot(x, shader::frame_bitangent(up))) / kOrthoHalf;
    d = std::max(4.0f * kOrthoHalf - glm::dot(x, up), 0.0f);  // MRGI_ISM_ORTHO_REACH half sides above
    depth = d;
    const glm::ivec2 t = glm::clamp(glm::ivec2(glm::floor((uv * 0.5f + 0.5f) * float(kSide))), glm::ivec2(0), glm::ivec2(int(kSide) - 1));
    const glm::ivec2 origin = glm::ivec2(3 % int(m.row), 3 / int(m.row)) * int(kSide);
    return m.texels[size_t(origin.y + t.y) * (m.row * kSide) + size_t(origin.x + t.x)];
  };
  float depth = 0.0f;
  // Over the box's middle: the floor (real) at its depth, the box's top (virtual) 0.15 m nearer.
  glm::vec2 d = texel(glm::vec3(1.0f, 0.0f, 1.0f), depth);
  EXPECT_NEAR(d.x, depth, 0.01f);
  EXPECT_NEAR(d.y, depth - 0.15f, 0.01f);
  // 0.2 m off the box: floor only; no virtual surface (splats and the fill reach a few texels of
  // 1.9 cm, not 12 cm).
  d = texel(glm::vec3(1.2f, 0.0f, 0.95f), depth);
  EXPECT_NEAR(d.x, depth, 0.01f);
  EXPECT_GT(d.y, 1e29f);
}

TEST_F(VulkanTest, IsmOfASparseCloudStillCoversTheFloor) {
  // 64 points a VPL, far fewer than the map's texels under the floor: the splats (sized to the
  // solid angle a point stands for) and the pull-push must fill the rest; the floor's directions
  // must still read as the floor (measured: 178 of 200 within 5 cm; the misses lie at the edge
  // of the 0.4 m disk, where the Halton points are sparsest).
  const Maps sparse = build(ctx(), 64);
  int floor_texels = 0, filled = 0;
  for (int k = 0; k < 200; ++k) {
    // Points of the floor within 0.4 m of the foot of VPL 0 (well inside the floor).
    const float a = float(k) * 2.39996f, rad = 0.4f * std::sqrt((float(k) + 0.5f) / 200.0f);
    const glm::vec3 p(1.0f + rad * std::cos(a), 0.0f, 1.0f + rad * std::sin(a));
    ++floor_texels;
    const float d = sparse.at(0, kVpl0, kDown, p).x;
    if (std::abs(d - glm::length(p - kVpl0)) < 0.05f) ++filled;
  }
  EXPECT_GT(filled, floor_texels * 85 / 100);
}

}  // namespace
