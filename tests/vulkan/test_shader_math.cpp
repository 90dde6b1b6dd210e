// shared/mrgi_shared.h's integer helpers run on lavapipe (shaders/probe/shared_math_probe.comp):
// the unit tests check their C++ compilation, but the driver lowers the GLSL its own way (a
// division through a reciprocal would make a float quotient of an exact multiple fall short).
#include <vector>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "vk_test_util.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

struct ProbeResult {
  std::vector<uint32_t> hits;
  std::vector<int32_t> quotients;
};

// One dispatch over width x height invocations (8 x 8 workgroups), quotients by `divisor`.
ProbeResult run_probe(Context& ctx, int width, int height, int divisor) {
  ProbeResult out;
  FrameGraphSettings fs;
  fs.max_output_width = 16;
  fs.max_output_height = 16;
  fs.frames_in_flight = 1;
  auto g = FrameGraph::create(ctx, fs);
  EXPECT_TRUE(g.ok()) << g.error().message;
  if (!g.ok()) return out;
  FrameGraph& graph = **g;
  const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  auto pipe = load_compute_pipeline(ctx, "probe/shared_math_probe.comp", {{ssbo}, {ssbo}}, 16);
  EXPECT_TRUE(pipe.ok()) << pipe.error().message;
  if (!pipe.ok()) return out;
  const uint32_t groups_x = uint32_t(width + 7) / 8, groups_y = uint32_t(height + 7) / 8;
  const size_t invocations = size_t(groups_x) * 64 * groups_y;
  auto make = [&](const char* name, size_t bytes) {
    BufferDesc d;
    d.name = name;
    d.size = bytes;
    d.memory = MemoryUsage::Readback;
    auto b = graph.create_buffer(d, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(b.ok()) << b.error().message;
    return *b;
  };
  const BufferHandle hits = make("probe_hits", size_t(width) * height * 4);
  const BufferHandle quotients = make("probe_quotients", invocations * 4);
  EXPECT_TRUE(graph.begin_frame().ok());
  graph.add_pass(
      "probe_clear", PassKind::Transfer, [&](PassBuilder& b) { b.write(hits, Access::TransferDst); },
      [hits](VkCommandBuffer cmd, PassContext& pass) {
        vkCmdFillBuffer(cmd, pass.buffer(hits), 0, VK_WHOLE_SIZE, 0u);
      });
  const Pipeline* p = &**pipe;
  const glm::ivec4 pc(width, height, divisor, 0);
  graph.add_pass(
      "probe", PassKind::Compute,
      [&](PassBuilder& b) {
        b.write(hits, Access::StorageReadWrite);
        b.write(quotients, Access::StorageWrite);
      },
      [&, p](VkCommandBuffer cmd, PassContext& pass) {
        DescriptorPush()
            .storage_buffer(0, pass.buffer(hits))
            .storage_buffer(1, pass.buffer(quotients))
            .push(pass.context(), cmd, *p);
        dispatch_2d(cmd, *p, &pc, sizeof(pc), groups_x * 8, groups_y * 8);
      });
  graph.mark_output(hits);
  graph.mark_output(quotients);
  EXPECT_TRUE(graph.compile().ok());
  EXPECT_TRUE(graph.submit().ok());
  auto done = graph.flush();
  EXPECT_TRUE(done.ok());
  const uint32_t slot = graph.slot();
  for (BufferHandle h : {hits, quotients}) EXPECT_TRUE(ctx.invalidate(graph.gpu_buffer(h, slot)).ok());
  const auto* hp = static_cast<const uint32_t*>(graph.mapped(hits, slot));
  const auto* qp = static_cast<const int32_t*>(graph.mapped(quotients, slot));
  if (hp) out.hits.assign(hp, hp + size_t(width) * height);
  if (qp) out.quotients.assign(qp, qp + invocations);
  return out;
}

TEST_F(VulkanTest, SpreadWorkgroupsCoverEveryInvocationOnceAndDivisionIsExact) {
  // Grids: the ssrt fast level's 160 x 120 cells (20 x 15 groups), fewer than 4 groups, an odd
  // count, a single row; divisors that are and are not powers of two.
  const int sizes[][3] = {{160, 120, 5}, {16, 8, 3}, {40, 24, 7}, {200, 8, 4}, {24, 40, 1000}};
  for (const auto& s : sizes) {
    const ProbeResult r = run_probe(ctx(), s[0], s[1], s[2]);
    ASSERT_EQ(r.hits.size(), size_t(s[0]) * s[1]);
    int wrong = 0;
    for (uint32_t h : r.hits) wrong += h != 1u;
    EXPECT_EQ(wrong, 0) << s[0] << "x" << s[1] << ": elements not hit exactly once; first: " << r.hits[0] << " " << r.hits[1] << " " << r.hits[8] << " " << r.hits[size_t(s[0]) * s[1] - 1];
    int wrong_q = 0;
    for (size_t i = 0; i < r.quotients.size(); ++i) wrong_q += r.quotients[i] != int(i) / s[2];
    EXPECT_EQ(wrong_q, 0) << "div_nonneg1(i, " << s[2] << ") wrong for " << wrong_q << " of "
                          << r.quotients.size();
  }
}

}  // namespace
