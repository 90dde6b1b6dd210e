// The frame graph's compile step as a pure function: culling and barrier derivation, checked
// without a GPU.
#include <gtest/gtest.h>

#include "gpu/frame_graph.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;

ResourceInfo image(const std::string& name, bool output = false, bool history = false) {
  ResourceInfo r;
  r.name = name;
  r.is_image = true;
  r.is_output = output;
  r.history = history;
  return r;
}
ResourceInfo buffer(const std::string& name, bool output = false, bool host_read = false) {
  ResourceInfo r;
  r.name = name;
  r.is_image = false;
  r.is_output = output;
  r.host_read = host_read;
  return r;
}
ResourceUse img(uint32_t id, Access a) { return {ResourceRef{true, id}, a}; }
ResourceUse buf(uint32_t id, Access a) { return {ResourceRef{false, id}, a}; }
PassDecl pass(const std::string& name, PassKind kind, std::vector<ResourceUse> uses, bool side_effect = false) {
  return PassDecl{name, kind, std::move(uses), side_effect};
}

CompiledGraph compile_ok(const std::vector<PassDecl>& p, const std::vector<ResourceInfo>& r) {
  auto g = compile_graph(p, r);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.error().message);
  return g.ok() ? *g : CompiledGraph{};
}

TEST(FrameGraphCulling, UnreadOutputIsCulledTransitively) {
  // a -> A -> b -> B -> c (nobody reads c)      out <- C (output)
  std::vector<ResourceInfo> res = {image("a"), image("b"), image("c"), image("out", true)};
  std::vector<PassDecl> passes = {
      pass("A", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("B", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
      pass("dead", PassKind::Compute, {img(1, Access::Sampled), img(2, Access::StorageWrite)}),
      pass("C", PassKind::Compute, {img(3, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  EXPECT_TRUE(g.runs("C"));
  EXPECT_FALSE(g.runs("dead"));
  EXPECT_FALSE(g.runs("B"));  // only "dead" read b
  EXPECT_FALSE(g.runs("A"));  // only B read a
  EXPECT_EQ(g.culled, (std::vector<std::string>{"A", "B", "dead"}));
}

TEST(FrameGraphCulling, MarkedOutputKeepsItsProducers) {
  std::vector<ResourceInfo> res = {image("a"), image("b"), image("c", true)};
  std::vector<PassDecl> passes = {
      pass("A", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("B", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
      pass("C", PassKind::Compute, {img(1, Access::StorageRead), img(2, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  ASSERT_EQ(g.passes.size(), 3u);
  EXPECT_TRUE(g.culled.empty());
  // Unmarking the output culls everything.
  res[2].is_output = false;
  g = compile_ok(passes, res);
  EXPECT_TRUE(g.passes.empty());
  EXPECT_EQ(g.culled.size(), 3u);
}

TEST(FrameGraphCulling, OverwrittenVersionIsCulledAndSideEffectsKept) {
  // A writes x, B overwrites x (write-only), x is output: A's version is never read.
  std::vector<ResourceInfo> res = {image("x", true), buffer("log")};
  std::vector<PassDecl> passes = {
      pass("A", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("B", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("debug", PassKind::Compute, {buf(1, Access::StorageWrite)}, /*side_effect=*/true),
  };
  CompiledGraph g = compile_ok(passes, res);
  EXPECT_FALSE(g.runs("A"));
  EXPECT_TRUE(g.runs("B"));
  EXPECT_TRUE(g.runs("debug"));
  // A read-modify-write keeps the earlier version alive.
  passes[1] = pass("B", PassKind::Compute, {img(0, Access::StorageReadWrite)});
  g = compile_ok(passes, res);
  EXPECT_TRUE(g.runs("A"));
}

TEST(FrameGraphCulling, HistoryIsAnOutputAndItsFirstReadNeedsNoProducer) {
  // Temporal filter: read last frame's history, write the new one.
  std::vector<ResourceInfo> res = {image("history", false, true), image("current")};
  std::vector<PassDecl> passes = {
      pass("shade", PassKind::Compute, {img(1, Access::StorageWrite)}),
      pass("accumulate", PassKind::Compute, {img(1, Access::Sampled), img(0, Access::StorageReadWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  EXPECT_TRUE(g.runs("shade"));
  EXPECT_TRUE(g.runs("accumulate"));
}

TEST(FrameGraphBarriers, ReadAfterWriteOnStorageImage) {
  std::vector<ResourceInfo> res = {image("img"), image("out", true)};
  std::vector<PassDecl> passes = {
      pass("write", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("read", PassKind::Compute, {img(0, Access::StorageRead), img(1, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("img");
  ASSERT_EQ(b.size(), 2u);
  // First touch: UNDEFINED -> GENERAL, nothing to wait for.
  EXPECT_EQ(b[0].old_layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_EQ(b[0].new_layout, VK_IMAGE_LAYOUT_GENERAL);
  EXPECT_EQ(b[0].src_stages, 0u);
  // RAW: compute write -> compute read, layout unchanged.
  EXPECT_EQ(b[1].src_stages, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(b[1].src_access, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  EXPECT_EQ(b[1].dst_stages, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(b[1].dst_access, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  EXPECT_EQ(b[1].old_layout, VK_IMAGE_LAYOUT_GENERAL);
  EXPECT_EQ(b[1].new_layout, VK_IMAGE_LAYOUT_GENERAL);
  // The barrier sits before the reading pass.
  ASSERT_EQ(g.passes.size(), 2u);
  EXPECT_EQ(g.passes[1].barriers.size(), 2u);  // img RAW + out first touch
}

TEST(FrameGraphBarriers, WriteAfterReadWaitsForTheReader) {
  std::vector<ResourceInfo> res = {image("img", true), image("tmp", true)};
  std::vector<PassDecl> passes = {
      pass("produce", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("consume", PassKind::Compute, {img(0, Access::StorageRead), img(1, Access::StorageWrite)}),
      pass("overwrite", PassKind::Compute, {img(0, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("img");
  ASSERT_EQ(b.size(), 3u);
  const Barrier& war = b[2];
  EXPECT_EQ(war.src_stages & VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(war.dst_access, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  EXPECT_EQ(war.old_layout, VK_IMAGE_LAYOUT_GENERAL);  // not a first touch: contents kept
}

TEST(FrameGraphBarriers, ColorAttachmentToSampledTransition) {
  std::vector<ResourceInfo> res = {image("gbuffer"), image("lit", true)};
  std::vector<PassDecl> passes = {
      pass("raster", PassKind::Graphics, {img(0, Access::ColorAttachmentWrite)}),
      pass("shade", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("gbuffer");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].new_layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  EXPECT_EQ(b[1].old_layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  EXPECT_EQ(b[1].new_layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_EQ(b[1].src_stages, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
  EXPECT_EQ(b[1].src_access, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  EXPECT_EQ(b[1].dst_stages, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(b[1].dst_access, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

TEST(FrameGraphBarriers, NoBarrierBetweenTwoReads) {
  std::vector<ResourceInfo> res = {image("src"), image("o1", true), image("o2", true)};
  std::vector<PassDecl> passes = {
      pass("make", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("r1", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
      pass("r2", PassKind::Compute, {img(0, Access::Sampled), img(2, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("src");
  ASSERT_EQ(b.size(), 2u);  // first touch, then write -> sampled; nothing before r2
  ASSERT_EQ(g.passes.size(), 3u);
  for (const Barrier& x : g.passes[2].barriers) EXPECT_NE(x.resource_name, "src");
  // A read in a new stage (fragment) after the compute read still needs the write made visible.
  passes.push_back(pass("r3", PassKind::Graphics, {img(0, Access::Sampled), img(2, Access::ColorAttachmentWrite)}));
  g = compile_ok(passes, res);
  b = g.barriers_for("src");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[2].dst_stages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
  EXPECT_EQ(b[2].old_layout, b[2].new_layout);
}

TEST(FrameGraphBarriers, DepthWriteThenSampledAndCulledPassesGetNoBarriers) {
  std::vector<ResourceInfo> res = {image("shadow"), image("lit", true), image("unused")};
  std::vector<PassDecl> passes = {
      pass("shadow_map", PassKind::Graphics, {img(0, Access::DepthAttachmentWrite)}),
      pass("nobody", PassKind::Compute, {img(2, Access::StorageWrite)}),
      pass("light", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("shadow");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].new_layout, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
  EXPECT_EQ(b[1].src_stages, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT);
  EXPECT_EQ(b[1].src_access, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
  EXPECT_EQ(b[1].new_layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_TRUE(g.barriers_for("unused").empty());
}

TEST(FrameGraphBarriers, StateCarriesAcrossFramesAndReadbackEndsAtHost) {
  // Frame 1: copy an image into a readback buffer.
  std::vector<ResourceInfo> res = {image("frame"), buffer("readback", true, true)};
  std::vector<PassDecl> passes = {
      pass("render", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("copy", PassKind::Transfer, {img(0, Access::TransferSrc), buf(1, Access::TransferDst)}),
  };
  CompiledGraph g1 = compile_ok(passes, res);
  ASSERT_EQ(g1.final_barriers.size(), 1u);
  EXPECT_EQ(g1.final_barriers[0].dst_stages, VK_PIPELINE_STAGE_2_HOST_BIT);
  EXPECT_EQ(g1.final_barriers[0].dst_access, VK_ACCESS_2_HOST_READ_BIT);
  EXPECT_EQ(g1.final_barriers[0].src_access, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  EXPECT_EQ(g1.final_states[0].layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  // Frame 2 starts from frame 1's end: the write must wait for frame 1's transfer read (WAR
  // across frames) and the old contents are discarded (not history).
  res[0].initial = g1.final_states[0];
  res[1].initial = g1.final_states[1];
  CompiledGraph g2 = compile_ok(passes, res);
  std::vector<Barrier> b = g2.barriers_for("frame");
  ASSERT_GE(b.size(), 1u);
  EXPECT_EQ(b[0].src_stages, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
  EXPECT_EQ(b[0].old_layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_EQ(b[0].new_layout, VK_IMAGE_LAYOUT_GENERAL);
}

TEST(FrameGraphBarriers, HistoryImagesKeepTheirContents) {
  std::vector<ResourceInfo> res = {image("accum", false, true)};
  res[0].initial.layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  res[0].initial.read_stages = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  std::vector<PassDecl> passes = {pass("write", PassKind::Compute, {img(0, Access::StorageWrite)})};
  CompiledGraph g = compile_ok(passes, res);
  std::vector<Barrier> b = g.barriers_for("accum");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].old_layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);  // not discarded
}

TEST(FrameGraphValidation, BadDeclarationsAreErrorsNamingPassAndResource) {
  std::vector<ResourceInfo> res = {image("img", true), buffer("buf", true)};
  auto expect_bad = [&](std::vector<PassDecl> p, const std::string& needle) {
    auto g = compile_graph(p, res);
    ASSERT_FALSE(g.ok()) << needle;
    EXPECT_EQ(g.error().kind, ErrorKind::BadUsage);
    EXPECT_NE(g.error().message.find(needle), std::string::npos) << g.error().message;
  };
  expect_bad({pass("twice", PassKind::Compute, {img(0, Access::StorageRead), img(0, Access::StorageWrite)})}, "twice");
  expect_bad({pass("att", PassKind::Compute, {img(0, Access::ColorAttachmentWrite)})}, "att");
  expect_bad({pass("vb", PassKind::Graphics, {img(0, Access::VertexBuffer)})}, "img");
  expect_bad({pass("samp", PassKind::Compute, {buf(1, Access::Sampled)})}, "buf");
  expect_bad({pass("kind", PassKind::Compute, {ResourceUse{ResourceRef{false, 0}, Access::StorageRead}})}, "kind");
  expect_bad({pass("oob", PassKind::Compute, {img(7, Access::StorageRead)})}, "oob");
  expect_bad({pass("xfer", PassKind::Transfer, {img(0, Access::StorageWrite)})}, "xfer");
}

// --- mip levels: state per level, so a mip chain reads level i - 1 while writing level i -------

ResourceInfo mipped(const std::string& name, uint32_t levels, bool output = false) {
  ResourceInfo r = image(name, output);
  r.mip_levels = levels;
  return r;
}
ResourceUse img_mips(uint32_t id, Access a, uint32_t base, uint32_t count) {
  return {ResourceRef{true, id}, a, base, count};
}

TEST(FrameGraphMips, MipChainBarriersArePerLevel) {
  std::vector<ResourceInfo> res = {mipped("volume", 4), image("out", true)};
  std::vector<PassDecl> passes = {
      pass("inject", PassKind::Compute, {img_mips(0, Access::StorageWrite, 0, 1)}),
      pass("down1", PassKind::Compute, {img_mips(0, Access::StorageRead, 0, 1), img_mips(0, Access::StorageWrite, 1, 1)}),
      pass("down2", PassKind::Compute, {img_mips(0, Access::StorageRead, 1, 1), img_mips(0, Access::StorageWrite, 2, 1)}),
      pass("down3", PassKind::Compute, {img_mips(0, Access::StorageRead, 2, 1), img_mips(0, Access::StorageWrite, 3, 1)}),
      pass("trace", PassKind::Compute, {img(0, Access::Sampled), img(1, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  EXPECT_TRUE(g.culled.empty());
  // down1: level 0 read after inject's write (storage -> storage, no layout change), level 1
  // made GENERAL from UNDEFINED (discarded: a first write-only touch).
  const auto& d1 = g.passes[1].barriers;
  ASSERT_EQ(d1.size(), 2u);
  EXPECT_EQ(d1[0].base_mip, 0u);
  EXPECT_EQ(d1[0].mip_count, 1u);
  EXPECT_EQ(d1[0].src_access, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  EXPECT_EQ(d1[0].dst_access, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  EXPECT_EQ(d1[0].new_layout, VK_IMAGE_LAYOUT_GENERAL);
  EXPECT_EQ(d1[1].base_mip, 1u);
  EXPECT_EQ(d1[1].old_layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_EQ(d1[1].new_layout, VK_IMAGE_LAYOUT_GENERAL);
  // trace samples every level: each level exactly once in its barriers, all to SHADER_READ_ONLY,
  // and level 3 (written, never read) waits for down3's write.
  std::vector<int> covered(4, 0);
  for (const Barrier& b : g.passes[4].barriers) {
    if (b.resource_name != "volume") continue;
    EXPECT_EQ(b.new_layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(b.old_layout, VK_IMAGE_LAYOUT_GENERAL);
    for (uint32_t m = b.base_mip; m < b.base_mip + b.mip_count; ++m) ++covered[m];
    if (b.base_mip + b.mip_count == 4) {
      EXPECT_NE(b.src_access & VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, 0u);
    }
  }
  EXPECT_EQ(covered, (std::vector<int>{1, 1, 1, 1}));
  ASSERT_EQ(g.final_mip_states[0].size(), 4u);
  for (const ResourceState& s : g.final_mip_states[0]) EXPECT_EQ(s.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_TRUE(g.final_mip_states[1].empty());  // one level: final_states only
}

TEST(FrameGraphMips, NeighbouringLevelsShareOneBarrier) {
  // Levels 1..3 were last touched alike (one clear of every level): one barrier covers them;
  // level 0, sampled in between (another layout), gets its own.
  std::vector<ResourceInfo> res = {mipped("volume", 4, true)};
  std::vector<PassDecl> passes = {
      pass("clear", PassKind::Compute, {img(0, Access::StorageWrite)}),
      pass("look", PassKind::Compute, {img_mips(0, Access::Sampled, 0, 1)}, true),
      pass("read all", PassKind::Compute, {img(0, Access::StorageReadWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  const auto& b = g.passes[2].barriers;
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].base_mip, 0u);
  EXPECT_EQ(b[0].mip_count, 1u);
  EXPECT_EQ(b[1].base_mip, 1u);
  EXPECT_EQ(b[1].mip_count, 3u);
  EXPECT_EQ(g.passes[0].barriers.size(), 1u);  // clear: one barrier for all four levels
  EXPECT_EQ(g.passes[0].barriers[0].mip_count, 4u);
}

TEST(FrameGraphMips, CullingFollowsLevels) {
  // Only level 0 is read by the output's pass: the pass writing level 1 alone is culled.
  std::vector<ResourceInfo> res = {mipped("pyramid", 3), image("out", true)};
  std::vector<PassDecl> passes = {
      pass("base", PassKind::Compute, {img_mips(0, Access::StorageWrite, 0, 1)}),
      pass("level1", PassKind::Compute, {img_mips(0, Access::StorageRead, 0, 1), img_mips(0, Access::StorageWrite, 1, 1)}),
      pass("use", PassKind::Compute, {img_mips(0, Access::Sampled, 0, 1), img(1, Access::StorageWrite)}),
  };
  CompiledGraph g = compile_ok(passes, res);
  EXPECT_TRUE(g.runs("base"));
  EXPECT_TRUE(g.runs("use"));
  EXPECT_FALSE(g.runs("level1"));
}

TEST(FrameGraphMips, OverlappingOrOutOfRangeLevelsAreRefused) {
  std::vector<ResourceInfo> res = {mipped("volume", 3), image("flat", true)};
  auto overlap = compile_graph(std::vector<PassDecl>{pass("bad", PassKind::Compute,
                                                          {img_mips(0, Access::StorageRead, 0, 2),
                                                           img_mips(0, Access::StorageWrite, 1, 1)})},
                               res);
  ASSERT_FALSE(overlap.ok());
  EXPECT_EQ(overlap.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(overlap.error().message.find("declared twice"), std::string::npos) << overlap.error().message;
  auto beyond = compile_graph(std::vector<PassDecl>{pass("bad", PassKind::Compute,
                                                         {img_mips(0, Access::StorageWrite, 2, 2)})},
                              res);
  ASSERT_FALSE(beyond.ok());
  EXPECT_NE(beyond.error().message.find("mip levels 2..4 outside the resource's 3"), std::string::npos)
      << beyond.error().message;
  auto flat = compile_graph(std::vector<PassDecl>{pass("bad", PassKind::Compute,
                                                       {img_mips(1, Access::StorageWrite, 1, 1)})},
                            res);
  ASSERT_FALSE(flat.ok());
  EXPECT_NE(flat.error().message.find("'flat'"), std::string::npos) << flat.error().message;
}

TEST(FrameGraphMips, PerLevelInitialStatesCarryAcrossFrames) {
  // Frame 1 leaves level 0 SHADER_READ_ONLY and level 1 GENERAL; frame 2 starts from that.
  std::vector<ResourceInfo> res = {mipped("history", 2, true)};
  res[0].history = true;
  std::vector<PassDecl> frame1 = {
      pass("write1", PassKind::Compute, {img_mips(0, Access::StorageWrite, 1, 1)}),
      pass("read0", PassKind::Compute, {img_mips(0, Access::Sampled, 0, 1)}, true),
  };
  CompiledGraph g1 = compile_ok(frame1, res);
  ASSERT_EQ(g1.final_mip_states[0].size(), 2u);
  EXPECT_EQ(g1.final_mip_states[0][0].layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_EQ(g1.final_mip_states[0][1].layout, VK_IMAGE_LAYOUT_GENERAL);
  res[0].initial = g1.final_states[0];
  res[0].initial_mips = g1.final_mip_states[0];
  std::vector<PassDecl> frame2 = {pass("read both", PassKind::Compute, {img(0, Access::StorageRead)}, true)};
  CompiledGraph g2 = compile_ok(frame2, res);
  const auto& b = g2.passes[0].barriers;
  ASSERT_EQ(b.size(), 2u);  // level 0 changes layout; level 1 waits for frame 1's write
  EXPECT_EQ(b[0].base_mip, 0u);
  EXPECT_EQ(b[0].old_layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_EQ(b[1].base_mip, 1u);
  EXPECT_EQ(b[1].old_layout, VK_IMAGE_LAYOUT_GENERAL);
  EXPECT_EQ(b[1].src_access, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

}  // namespace
