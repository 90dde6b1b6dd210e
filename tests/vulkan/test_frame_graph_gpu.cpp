// The frame graph on lavapipe with validation (and synchronization validation) on: a real graph
// of compute and transfer passes with readback, timestamps without stalls, the floor pass, and
// no allocation after start-up.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

#include "gpu/floor_pass.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "vk_test_util.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

constexpr uint32_t W = 40, H = 24;  // not multiples of the 8x8 work group

uint8_t pattern(uint32_t x, uint32_t y, uint32_t c) { return uint8_t((x * 5 + y * 11 + c * 60) & 0xff); }

// floor.comp computes dst = 1 - src per channel: the graph input -> invert -> invert back ->
// copy to a readback buffer, plus a pass nobody reads.
struct InvertGraph {
  std::unique_ptr<FrameGraph> graph;
  PipelineHandle invert;
  ImageHandle input, mid, result, unused;
  BufferHandle readback;

  static InvertGraph make(Context& ctx) {
    InvertGraph t;
    FrameGraphSettings fs;
    fs.max_output_width = W;
    fs.max_output_height = H;
    fs.frames_in_flight = 2;
    auto g = FrameGraph::create(ctx, fs);
    EXPECT_TRUE(g.ok()) << g.error().message;
    t.graph = std::move(*g);
    ComputePipelineDesc pd;
    pd.name = "invert";
    pd.spirv = *shader_spirv("floor.comp");
    pd.bindings = {{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
    pd.push_constant_bytes = 8;
    auto p = create_compute_pipeline(ctx, pd);
    EXPECT_TRUE(p.ok()) << p.error().message;
    t.invert = PipelineHandle(ctx, std::move(*p));
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                    VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    auto mk = [&](const char* name, bool history) {
      ImageDesc d;
      d.name = name;
      d.history = history;
      auto h = t.graph->create_image(d, usage);
      EXPECT_TRUE(h.ok()) << h.error().message;
      return *h;
    };
    t.input = mk("input", true);
    t.mid = mk("mid", false);
    t.result = mk("result", false);
    t.unused = mk("unused", false);
    BufferDesc bd;
    bd.name = "readback";
    bd.size = W * H * 4;
    bd.memory = MemoryUsage::Readback;
    bd.per_frame_copies = true;
    auto rb = t.graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(rb.ok()) << rb.error().message;
    t.readback = *rb;
    std::vector<uint8_t> texels(W * H * 4);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x)
        for (uint32_t c = 0; c < 4; ++c) texels[(y * W + x) * 4 + c] = pattern(x, y, c);
    EXPECT_TRUE(t.graph->upload_image(t.input, texels.data(), texels.size()).ok());
    return t;
  }

  void add_invert(const char* name, ImageHandle src, ImageHandle dst) {
    const Pipeline* p = &*invert;
    graph->add_pass(
        name, PassKind::Compute,
        [&](PassBuilder& b) {
          b.read(src, Access::StorageRead);
          b.write(dst, Access::StorageWrite);
        },
        [p, src, dst](VkCommandBuffer cmd, PassContext& ctx) {
          const VkExtent2D e = ctx.extent(dst);
          const int32_t ext[2] = {int32_t(e.width), int32_t(e.height)};
          DescriptorPush().storage_image(0, ctx.view(src)).storage_image(1, ctx.view(dst)).push(ctx.context(), cmd, *p);
          dispatch_2d(cmd, *p, ext, sizeof ext, e.width, e.height);
        });
  }

  Status record_frame() {
    add_invert("invert", input, mid);
    add_invert("invert_back", mid, result);
    add_invert("dead_end", mid, unused);
    const ImageHandle r = result;
    const BufferHandle rb = readback;
    graph->add_pass(
        "readback", PassKind::Transfer,
        [&](PassBuilder& b) {
          b.read(r, Access::TransferSrc);
          b.write(rb, Access::TransferDst);
        },
        [r, rb](VkCommandBuffer cmd, PassContext& ctx) {
          VkBufferImageCopy region{};
          region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
          region.imageExtent = {W, H, 1};
          vkCmdCopyImageToBuffer(cmd, ctx.image(r), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, ctx.buffer(rb), 1, &region);
        });
    graph->mark_output(readback);
    MRGI_TRY(graph->compile());
    return graph->submit();
  }
};

// Pixels of the slot's readback that differ from the input pattern (the graph inverts twice).
int wrong_pixels(Context& ctx, const InvertGraph& t, uint32_t slot) {
  EXPECT_TRUE(ctx.invalidate(t.graph->gpu_buffer(t.readback, slot)).ok());
  const uint8_t* px = static_cast<const uint8_t*>(t.graph->mapped(t.readback, slot));
  if (!px) return -1;
  int wrong = 0;
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x)
      for (uint32_t c = 0; c < 4; ++c) wrong += px[(y * W + x) * 4 + c] != pattern(x, y, c);
  return wrong;
}

TEST_F(VulkanTest, GraphRunsComputeChainAndReadsBackExactPixels) {
  InvertGraph t = InvertGraph::make(ctx());
  auto begun = t.graph->begin_frame();
  ASSERT_TRUE(begun.ok()) << begun.error().message;
  EXPECT_FALSE(begun->has_value());  // first use of the slot: nothing completed yet
  ASSERT_TRUE(t.record_frame().ok());
  EXPECT_EQ(t.graph->compiled().culled, std::vector<std::string>{"dead_end"});
  const uint32_t slot = t.graph->slot();
  auto done = t.graph->flush();
  ASSERT_TRUE(done.ok()) << done.error().message;
  ASSERT_EQ(done->size(), 1u);
  EXPECT_EQ((*done)[0].slot, slot);
  EXPECT_EQ(wrong_pixels(ctx(), t, slot), 0);
}

TEST_F(VulkanTest, TimestampsArriveFramesLaterWithoutStalling) {
  InvertGraph t = InvertGraph::make(ctx());
  std::vector<FrameTimings> got;
  const int frames = 6;
  for (int i = 0; i < frames; ++i) {
    auto begun = t.graph->begin_frame();
    ASSERT_TRUE(begun.ok()) << begun.error().message;
    if (i < 2) {
      EXPECT_FALSE(begun->has_value()) << "frame " << i;
    } else {
      ASSERT_TRUE(begun->has_value()) << "frame " << i;
      EXPECT_EQ((*begun)->frame_index, i - 2);  // two frames in flight
      got.push_back(**begun);
    }
    ASSERT_TRUE(t.record_frame().ok());
  }
  auto rest = t.graph->flush();
  ASSERT_TRUE(rest.ok());
  ASSERT_EQ(rest->size(), 2u);
  // Identical frames: compiled once the states settle, then reused.
  EXPECT_GE(t.graph->compile_cache_hits(), uint64_t(frames - 3));
  EXPECT_EQ((*rest)[0].frame_index, frames - 2);
  EXPECT_EQ((*rest)[1].frame_index, frames - 1);
  for (const FrameTimings& f : *rest) got.push_back(f);
  ASSERT_EQ(got.size(), size_t(frames));
  for (const FrameTimings& f : got) {
    ASSERT_EQ(f.passes.size(), 3u);
    EXPECT_EQ(f.passes[0].name, "invert");
    EXPECT_EQ(f.passes[1].name, "invert_back");
    EXPECT_EQ(f.passes[2].name, "readback");
    double sum = 0.0;
    for (const PassTiming& p : f.passes) {
      EXPECT_GT(p.gpu_ms, 0.0) << p.name;
      EXPECT_LT(p.gpu_ms, 1000.0) << p.name;
      sum += p.gpu_ms;
    }
    EXPECT_GE(f.total_ms, sum * 0.999);
    EXPECT_EQ(f.culled, std::vector<std::string>{"dead_end"});
  }
  // Readback of every frame was correct: check the last one.
  const uint32_t slot = got.back().slot;
  ASSERT_TRUE(ctx().invalidate(t.graph->gpu_buffer(t.readback, slot)).ok());
  const uint8_t* px = static_cast<const uint8_t*>(t.graph->mapped(t.readback, slot));
  EXPECT_EQ(px[(5 * W + 7) * 4 + 1], pattern(7, 5, 1));
}

TEST_F(VulkanTest, ProfilingModeTimesEachPassAloneAndTheyAddUpToTheFrame) {
  InvertGraph t = InvertGraph::make(ctx());
  std::vector<FrameTimings> got;
  // Normal, profiled, profiled, normal, profiled: the mode switches between frames, in flight.
  const bool profiled[] = {false, true, true, false, true};
  for (bool on : profiled) {
    ASSERT_TRUE(t.graph->set_profiling(on).ok());
    auto begun = t.graph->begin_frame();
    ASSERT_TRUE(begun.ok()) << begun.error().message;
    if (*begun) got.push_back(**begun);
    EXPECT_EQ(t.graph->set_profiling(!on).error().kind, ErrorKind::BadUsage);  // not inside a frame
    ASSERT_TRUE(t.record_frame().ok());
  }
  auto rest = t.graph->flush();
  ASSERT_TRUE(rest.ok()) << rest.error().message;
  for (const FrameTimings& f : *rest) got.push_back(f);
  ASSERT_EQ(got.size(), 5u);
  for (size_t i = 0; i < got.size(); ++i) {
    const FrameTimings& f = got[i];
    EXPECT_EQ(f.frame_index, int64_t(i));
    EXPECT_EQ(f.profiled, profiled[i]) << "frame " << i;
    ASSERT_EQ(f.passes.size(), 3u);
    double sum = 0.0;
    for (const PassTiming& p : f.passes) {
      EXPECT_GE(p.gpu_ms, 0.0) << p.name;  // the submission overhead is subtracted
      sum += p.gpu_ms;
    }
    if (f.profiled) {
      EXPECT_NEAR(f.total_ms, sum, 1e-9) << "profiled passes are the frame";
    }
    EXPECT_GT(f.completed_s, 0.0);
    if (i > 0) {
      EXPECT_GE(f.completed_s, got[i - 1].completed_s);
    }
  }
  // The output is the same in both modes.
  EXPECT_EQ(wrong_pixels(ctx(), t, got.back().slot), 0);
}

// The regression checks' test hook (frame_graph.h): MRGI_PLANT_SLOWDOWN=PASS:FACTOR[,...] makes
// each named pass take FACTOR times as long in profiling mode, the others unchanged; a malformed
// list is refused naming the part at fault.
TEST_F(VulkanTest, PlantedSlowdownLengthensOnlyTheNamedPasses) {
  auto median_ms = [&](const char* plant) {
    if (plant) setenv("MRGI_PLANT_SLOWDOWN", plant, 1);
    InvertGraph t = InvertGraph::make(ctx());
    unsetenv("MRGI_PLANT_SLOWDOWN");
    EXPECT_TRUE(t.graph->set_profiling(true).ok());
    std::map<std::string, std::vector<double>> ms;
    auto take = [&](const FrameTimings& f) {
      for (const PassTiming& p : f.passes) ms[p.name].push_back(p.gpu_ms);
    };
    for (int i = 0; i < 9; ++i) {
      auto begun = t.graph->begin_frame();
      EXPECT_TRUE(begun.ok());
      if (begun.ok() && *begun) take(**begun);
      EXPECT_TRUE(t.record_frame().ok());
    }
    auto rest = t.graph->flush();
    EXPECT_TRUE(rest.ok());
    if (rest.ok())
      for (const FrameTimings& f : *rest) take(f);
    std::map<std::string, double> med;
    for (auto& [name, v] : ms) {
      std::sort(v.begin(), v.end());
      med[name] = v[v.size() / 2];
    }
    return med;
  };
  const auto plain = median_ms(nullptr);
  const auto planted = median_ms("invert_back:4,readback:1");
  ASSERT_TRUE(plain.count("invert_back") && planted.count("invert_back"));
  // 4x the pass's whole submission, less the submission overhead subtracted afterwards: well
  // above 2x; the unnamed pass is not lengthened that way.
  EXPECT_GT(planted.at("invert_back"), 2.0 * plain.at("invert_back"));
  EXPECT_LT(planted.at("invert"), 2.0 * plain.at("invert") + 0.5);
  for (const char* bad : {"invert_back", "invert_back:0.5", ":2", "invert_back:2,readback"}) {
    setenv("MRGI_PLANT_SLOWDOWN", bad, 1);
    FrameGraphSettings fs;
    fs.max_output_width = W;
    fs.max_output_height = H;
    auto g = FrameGraph::create(ctx(), fs);
    unsetenv("MRGI_PLANT_SLOWDOWN");
    ASSERT_FALSE(g.ok()) << bad;
    EXPECT_EQ(g.error().kind, ErrorKind::BadUsage);
    EXPECT_NE(g.error().message.find("PASS:FACTOR"), std::string::npos) << g.error().message;
  }
}

TEST_F(VulkanTest, ProfilingModeNeedsItsCommandBuffersAllocated) {
  FrameGraphSettings fs;
  fs.max_output_width = W;
  fs.max_output_height = H;
  fs.allow_profiling = false;
  auto g = FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(g.ok()) << g.error().message;
  const Status st = (*g)->set_profiling(true);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(st.error().message.find("allow_profiling"), std::string::npos) << st.error().message;
  EXPECT_TRUE((*g)->set_profiling(false).ok());
}

// A buffer with a texel format gets a view per frame copy; a format without a known texel
// size, or more texels than the device's maxTexelBufferElements, is refused by name.
TEST_F(VulkanTest, TexelBufferViewsPerCopyAndTheirLimits) {
  FrameGraphSettings fs;
  fs.max_output_width = W;
  fs.max_output_height = H;
  auto g = FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(g.ok()) << g.error().message;
  BufferDesc d{"words", 1024, MemoryUsage::Upload, true};
  d.texel_format = VK_FORMAT_R32_UINT;
  auto b = (*g)->create_buffer(d, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_EQ((*g)->texel_format(*b), VK_FORMAT_R32_UINT);
  for (uint32_t slot = 0; slot < fs.frames_in_flight; ++slot)
    EXPECT_NE((*g)->gpu_buffer(*b, slot).texel_view, VkBufferView(VK_NULL_HANDLE));
  EXPECT_NE((*g)->gpu_buffer(*b, 0).texel_view, (*g)->gpu_buffer(*b, 1).texel_view);

  BufferDesc odd{"odd_format", 1024};
  odd.texel_format = VK_FORMAT_R8G8B8A8_UNORM;
  auto o = (*g)->create_buffer(odd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  ASSERT_FALSE(o.ok());
  EXPECT_EQ(o.error().kind, ErrorKind::NotImplemented);
  EXPECT_NE(o.error().message.find("odd_format"), std::string::npos) << o.error().message;

  const VkDeviceSize limit = ctx().properties().limits.maxTexelBufferElements;
  BufferDesc huge{"too_many_texels", (limit + 1) * 4};
  huge.texel_format = VK_FORMAT_R32_UINT;
  auto h = (*g)->create_buffer(huge, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  ASSERT_FALSE(h.ok());
  EXPECT_EQ(h.error().kind, ErrorKind::Device);
  EXPECT_NE(h.error().message.find("maxTexelBufferElements"), std::string::npos)
      << h.error().message;
}

TEST_F(VulkanTest, NoAllocationAfterStartUp) {
  InvertGraph t = InvertGraph::make(ctx());
  auto floor = FloorPass::create(*t.graph);
  ASSERT_TRUE(floor.ok()) << floor.error().message;
  const uint64_t bytes = ctx().allocated_bytes();
  const uint64_t count = ctx().allocation_count();
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(t.graph->begin_frame().ok());
    floor->add_to(*t.graph);
    ASSERT_TRUE(t.record_frame().ok());
    EXPECT_EQ(ctx().allocated_bytes(), bytes);
    EXPECT_EQ(ctx().allocation_count(), count);
  }
  ASSERT_TRUE(t.graph->flush().ok());
  EXPECT_EQ(ctx().allocated_bytes(), bytes);
  // The floor pass alternates between two graphs; once resource states settle both are cached.
  EXPECT_GE(t.graph->compile_cache_hits(), 3u);
}

TEST_F(VulkanTest, RelativeImagesFollowOutputSizeAndRenderScaleWithoutReallocating) {
  FrameGraphSettings fs;
  fs.max_output_width = 640;
  fs.max_output_height = 480;
  auto g = FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(g.ok());
  ImageDesc half;
  half.name = "half";
  half.scale = 0.5f;
  ImageDesc fixed;
  fixed.name = "fixed";
  fixed.size_mode = SizeMode::Absolute;
  fixed.width = 256;
  fixed.height = 256;
  ImageDesc full_res;
  full_res.name = "full";
  full_res.follows_render_scale = false;
  auto h = (*g)->create_image(half, VK_IMAGE_USAGE_STORAGE_BIT);
  auto f = (*g)->create_image(fixed, VK_IMAGE_USAGE_STORAGE_BIT);
  auto fr = (*g)->create_image(full_res, VK_IMAGE_USAGE_STORAGE_BIT);
  ASSERT_TRUE(h.ok() && f.ok() && fr.ok());
  EXPECT_EQ((*g)->allocated_extent(*h).width, 320u);
  const uint64_t bytes = ctx().allocated_bytes();
  ASSERT_TRUE((*g)->set_render_scale(0.5f).ok());
  EXPECT_EQ((*g)->extent(*h).width, 160u);
  EXPECT_EQ((*g)->extent(*h).height, 120u);
  EXPECT_EQ((*g)->extent(*fr).width, 640u);
  EXPECT_EQ((*g)->extent(*f).width, 256u);
  ASSERT_TRUE((*g)->set_output_size(320, 240).ok());
  EXPECT_EQ((*g)->extent(*h).width, 80u);
  EXPECT_EQ((*g)->extent(*fr).height, 240u);
  EXPECT_EQ(ctx().allocated_bytes(), bytes);
  EXPECT_EQ((*g)->set_output_size(1280, 720).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ((*g)->set_render_scale(1.5f).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ((*g)->set_render_scale(0.0f).error().kind, ErrorKind::BadUsage);
  ImageDesc dup;
  dup.name = "half";
  EXPECT_EQ((*g)->create_image(dup, VK_IMAGE_USAGE_STORAGE_BIT).error().kind, ErrorKind::BadUsage);
  // An extent divisor (a stage at a fraction of the internal size): ceil(extent / d), no
  // reallocation, 1..64.
  ASSERT_TRUE((*g)->set_output_size(640, 480).ok());
  ASSERT_TRUE((*g)->set_render_scale(1.0f).ok());
  ASSERT_TRUE((*g)->set_extent_divisor(*fr, 4).ok());
  EXPECT_EQ((*g)->extent(*fr).width, 160u);
  EXPECT_EQ((*g)->extent(*fr).height, 120u);
  ASSERT_TRUE((*g)->set_output_size(638, 477).ok());
  EXPECT_EQ((*g)->extent(*fr).width, 160u);  // ceil(638 / 4)
  EXPECT_EQ((*g)->extent(*fr).height, 120u);  // ceil(477 / 4)
  EXPECT_EQ((*g)->extent(*h).width, 319u);    // others unaffected
  ASSERT_TRUE((*g)->set_extent_divisor(*fr, 1).ok());
  EXPECT_EQ((*g)->extent(*fr).width, 638u);
  EXPECT_EQ(ctx().allocated_bytes(), bytes);
  // Absolute images (a volume's cheaper levels): each dimension of the allocation / divisor.
  ASSERT_TRUE((*g)->set_extent_divisor(*f, 3).ok());
  EXPECT_EQ((*g)->extent(*f).width, 86u);  // ceil(256 / 3)
  EXPECT_EQ((*g)->extent3d(*f, 1).height, 43u);
  EXPECT_EQ((*g)->extent3d(*f).depth, 1u);
  ASSERT_TRUE((*g)->set_extent_divisor(*f, 1).ok());
  EXPECT_EQ((*g)->extent(*f).width, 256u);
  EXPECT_EQ(ctx().allocated_bytes(), bytes);
  EXPECT_EQ((*g)->set_extent_divisor(*fr, 0).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ((*g)->set_extent_divisor(*fr, 65).error().kind, ErrorKind::BadUsage);
  EXPECT_EQ((*g)->set_extent_divisor(ImageHandle{}, 2).error().kind, ErrorKind::BadUsage);
}

TEST_F(VulkanTest, FloorPassRunsAndIsTimed) {
  // 640 x 480: the pass (about 1.5 ms) is far above the empty-submission cost subtracted from it
  // (about 0.05 ms); at 160 x 120 a loaded machine's overhead estimate could exceed it, and the
  // pass read 0 (seen once in CI).
  auto m = measure_floor_pass(ctx(), 640, 480, 8, 2);
  ASSERT_TRUE(m.ok()) << m.error().message;
  EXPECT_EQ(m->samples_ms.size(), 8u);
  EXPECT_GT(m->median_ms, 0.0);
  EXPECT_LE(m->min_ms, m->median_ms);
  EXPECT_GE(m->max_ms, m->median_ms);
  EXPECT_FALSE(measure_floor_pass(ctx(), 0, 120).ok());
}

TEST_F(VulkanTest, UnknownShaderIsNotFoundListingKnownOnes) {
  auto s = shader_spirv("nope.comp");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().kind, ErrorKind::NotFound);
  EXPECT_NE(s.error().message.find("floor.comp"), std::string::npos);
  auto f = shader_spirv("floor.comp");
  ASSERT_TRUE(f.ok());
  EXPECT_EQ((*f)[0], 0x07230203u);
}

TEST_F(VulkanTest, FrameLoopMisuseIsAnError) {
  FrameGraphSettings fs;
  fs.max_output_width = 8;
  fs.max_output_height = 8;
  auto g = FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ((*g)->compile().error().kind, ErrorKind::BadUsage);  // no begin_frame
  ASSERT_TRUE((*g)->begin_frame().ok());
  EXPECT_EQ((*g)->begin_frame().error().kind, ErrorKind::BadUsage);  // not submitted
  ImageDesc d;
  d.name = "late";
  EXPECT_EQ((*g)->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT).error().kind, ErrorKind::BadUsage);
  ASSERT_TRUE((*g)->submit().ok());  // an empty frame is fine
  fs.frames_in_flight = 4;
  EXPECT_EQ(FrameGraph::create(ctx(), fs).error().kind, ErrorKind::BadUsage);
}

}  // namespace

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

// The tests above pass with synchronization validation on; this shows that validation would
// catch a missing barrier: the same two dependent dispatches recorded with no barrier between.
TEST_F(VulkanTest, SynchronizationValidationCatchesAMissingBarrier) {
  ComputePipelineDesc pd;
  pd.name = "invert";
  pd.spirv = *shader_spirv("floor.comp");
  pd.bindings = {{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
  pd.push_constant_bytes = 8;
  auto p = create_compute_pipeline(ctx(), pd);
  ASSERT_TRUE(p.ok());
  PipelineHandle pipeline(ctx(), std::move(*p));
  ImageCreateDesc d;
  d.width = 16;
  d.height = 16;
  d.usage = VK_IMAGE_USAGE_STORAGE_BIT;
  GpuImage img[3];
  for (auto& i : img) {
    d.name = "sync-test";
    auto made = ctx().create_image(d);
    ASSERT_TRUE(made.ok());
    i = *made;
  }
  Status s = ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier2 b[3];
    for (int i = 0; i < 3; ++i) {
      b[i] = {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
      b[i].dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
      b[i].dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
      b[i].oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      b[i].newLayout = VK_IMAGE_LAYOUT_GENERAL;
      b[i].srcQueueFamilyIndex = b[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b[i].image = img[i].image;
      b[i].subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    }
    VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    di.imageMemoryBarrierCount = 3;
    di.pImageMemoryBarriers = b;
    ctx().fn().cmd_pipeline_barrier2(cmd, &di);
    const int32_t ext[2] = {16, 16};
    DescriptorPush().storage_image(0, img[0].view).storage_image(1, img[1].view).push(ctx(), cmd, *pipeline);
    dispatch_2d(cmd, *pipeline, ext, sizeof ext, 16, 16);
    // Missing: compute write of img[1] -> compute read of img[1].
    DescriptorPush().storage_image(0, img[1].view).storage_image(1, img[2].view).push(ctx(), cmd, *pipeline);
    dispatch_2d(cmd, *pipeline, ext, sizeof ext, 16, 16);
  });
  ASSERT_TRUE(s.ok());
  const auto messages = ctx().validation_messages();
  bool hazard = false;
  for (const auto& m : messages) hazard |= m.find("READ_AFTER_WRITE") != std::string::npos;
  EXPECT_TRUE(hazard) << "synchronization validation did not report the missing barrier";
  ctx().clear_validation_messages();
  for (auto& i : img) ctx().destroy(i);
}

}  // namespace

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

// SPIR-V for test-only shaders, compiled with the same glslangValidator the build uses.
std::vector<uint32_t> compile_glsl(const std::string& stage, const std::string& source) {
  const std::string dir = ::testing::TempDir();
  const std::string src = dir + "/mrgi_test." + stage, spv = src + ".spv";
  FILE* f = std::fopen(src.c_str(), "w");
  if (!f) return {};
  std::fputs(source.c_str(), f);
  std::fclose(f);
  const std::string cmd = "glslangValidator -V --target-env vulkan1.2 -o " + spv + " " + src + " > /dev/null";
  if (std::system(cmd.c_str()) != 0) return {};
  FILE* in = std::fopen(spv.c_str(), "rb");
  if (!in) return {};
  std::vector<uint32_t> words;
  uint32_t w = 0;
  while (std::fread(&w, 4, 1, in) == 1) words.push_back(w);
  std::fclose(in);
  return words;
}

// Graphics through the graph: a triangle rasterised with depth test into colour + depth
// (dynamic rendering), then read by a compute pass (attachment -> storage transition), then
// copied to a readback buffer.
TEST_F(VulkanTest, GraphicsPassWithDepthFeedsComputeAndReadback) {
  const auto vs = compile_glsl("vert", R"(#version 450
layout(location = 0) in vec3 pos;
void main() { gl_Position = vec4(pos, 1.0); })");
  const auto fs = compile_glsl("frag", R"(#version 450
layout(location = 0) out vec4 color;
layout(push_constant) uniform P { vec4 c; } p;
void main() { color = p.c; })");
  ASSERT_FALSE(vs.empty());
  ASSERT_FALSE(fs.empty());
  GraphicsPipelineDesc gd;
  gd.name = "triangle";
  gd.vertex_spirv = vs;
  gd.fragment_spirv = fs;
  gd.push_constant_bytes = 16;
  gd.vertex_strides = {12};
  gd.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
  gd.color_formats = {VK_FORMAT_R8G8B8A8_UNORM};
  gd.depth_format = VK_FORMAT_D32_SFLOAT;
  gd.cull_mode = VK_CULL_MODE_NONE;
  gd.depth_bias_constant = 1.0f;  // exercised, irrelevant to the values checked
  auto gp = create_graphics_pipeline(ctx(), gd);
  ASSERT_TRUE(gp.ok()) << gp.error().message;
  PipelineHandle tri(ctx(), std::move(*gp));
  ComputePipelineDesc cd;
  cd.name = "invert";
  cd.spirv = *shader_spirv("floor.comp");
  cd.bindings = {{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
  cd.push_constant_bytes = 8;
  auto cp = create_compute_pipeline(ctx(), cd);
  ASSERT_TRUE(cp.ok());
  PipelineHandle inv(ctx(), std::move(*cp));

  FrameGraphSettings fs_settings;
  fs_settings.max_output_width = W;
  fs_settings.max_output_height = H;
  auto g = FrameGraph::create(ctx(), fs_settings);
  ASSERT_TRUE(g.ok());
  FrameGraph& graph = **g;
  ImageDesc color_desc;
  color_desc.name = "color";
  ImageDesc depth_desc;
  depth_desc.name = "depth";
  depth_desc.format = VK_FORMAT_D32_SFLOAT;
  ImageDesc out_desc;
  out_desc.name = "inverted";
  auto color = graph.create_image(color_desc, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT);
  auto depth = graph.create_image(depth_desc, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  auto out = graph.create_image(out_desc, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  BufferDesc vb_desc;
  vb_desc.name = "vertices";
  vb_desc.size = 6 * 12;
  vb_desc.history = true;  // uploaded once
  auto vb = graph.create_buffer(vb_desc, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  BufferDesc rb_desc;
  rb_desc.name = "readback";
  rb_desc.size = W * H * 4;
  rb_desc.memory = MemoryUsage::Readback;
  rb_desc.per_frame_copies = true;
  auto rb = graph.create_buffer(rb_desc, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ASSERT_TRUE(color.ok() && depth.ok() && out.ok() && vb.ok() && rb.ok());
  // Two triangles over the upper-left half: red at depth 0.25 drawn after green at depth 0.75,
  // then green again at 0.75 which the depth test must reject.
  const float verts[] = {-1, -1, 0.25f, 1, -1, 0.25f, -1, 1, 0.25f, -1, -1, 0.75f, 1, -1, 0.75f, -1, 1, 0.75f};
  ASSERT_TRUE(ctx().upload_buffer(graph.gpu_buffer(*vb, 0), verts, sizeof verts).ok());

  ASSERT_TRUE(graph.begin_frame().ok());
  const ImageHandle c = *color, d = *depth, o = *out;
  const BufferHandle v = *vb, r = *rb;
  const Pipeline* tp = &*tri;
  const Pipeline* ip = &*inv;
  graph.add_pass(
      "raster", PassKind::Graphics,
      [&](PassBuilder& b) {
        b.write(c, Access::ColorAttachmentWrite);
        b.write(d, Access::DepthAttachmentWrite);
        b.read(v, Access::VertexBuffer);
      },
      [=](VkCommandBuffer cmd, PassContext& p) {
        const VkExtent2D e = p.extent(c);
        VkRenderingAttachmentInfo ca{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        ca.imageView = p.view(c);
        ca.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        ca.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        ca.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        ca.clearValue.color = {{0.0f, 0.0f, 1.0f, 1.0f}};
        VkRenderingAttachmentInfo da{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        da.imageView = p.view(d);
        da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        da.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        da.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        da.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{0, 0}, e};
        ri.layerCount = 1;
        ri.colorAttachmentCount = 1;
        ri.pColorAttachments = &ca;
        ri.pDepthAttachment = &da;
        p.context().fn().cmd_begin_rendering(cmd, &ri);
        VkViewport vp{0, 0, float(e.width), float(e.height), 0, 1};
        VkRect2D sc{{0, 0}, e};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &sc);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, tp->pipeline);
        VkBuffer buf = p.buffer(v);
        VkDeviceSize off = 0;
        vkCmdBindVertexBuffers(cmd, 0, 1, &buf, &off);
        const float red[4] = {1, 0, 0, 1}, green[4] = {0, 1, 0, 1};
        vkCmdPushConstants(cmd, tp->layout, tp->stages, 0, 16, red);
        vkCmdDraw(cmd, 3, 1, 0, 0);
        vkCmdPushConstants(cmd, tp->layout, tp->stages, 0, 16, green);
        vkCmdDraw(cmd, 3, 1, 3, 0);
        p.context().fn().cmd_end_rendering(cmd);
      });
  graph.add_pass(
      "invert", PassKind::Compute,
      [&](PassBuilder& b) {
        b.read(c, Access::StorageRead);
        b.write(o, Access::StorageWrite);
      },
      [=](VkCommandBuffer cmd, PassContext& p) {
        const VkExtent2D e = p.extent(o);
        const int32_t ext[2] = {int32_t(e.width), int32_t(e.height)};
        DescriptorPush().storage_image(0, p.view(c)).storage_image(1, p.view(o)).push(p.context(), cmd, *ip);
        dispatch_2d(cmd, *ip, ext, sizeof ext, e.width, e.height);
      });
  graph.add_pass(
      "readback", PassKind::Transfer,
      [&](PassBuilder& b) {
        b.read(o, Access::TransferSrc);
        b.write(r, Access::TransferDst);
      },
      [=](VkCommandBuffer cmd, PassContext& p) {
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {W, H, 1};
        vkCmdCopyImageToBuffer(cmd, p.image(o), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(r), 1, &region);
      });
  graph.mark_output(r);
  ASSERT_TRUE(graph.submit().ok());
  const uint32_t slot = graph.slot();
  ASSERT_TRUE(graph.flush().ok());
  ASSERT_TRUE(ctx().invalidate(graph.gpu_buffer(r, slot)).ok());
  const uint8_t* px = static_cast<const uint8_t*>(graph.mapped(r, slot));
  // Inside the triangle (top-left): red survived the depth test -> inverted (0, 255, 255).
  const uint8_t* in = px + (2 * W + 2) * 4;
  EXPECT_EQ(in[0], 0);
  EXPECT_EQ(in[1], 255);
  EXPECT_EQ(in[2], 255);
  // Outside (bottom-right): the clear colour blue -> inverted (255, 255, 0).
  const uint8_t* outside = px + ((H - 2) * W + (W - 2)) * 4;
  EXPECT_EQ(outside[0], 255);
  EXPECT_EQ(outside[1], 255);
  EXPECT_EQ(outside[2], 0);
}

}  // namespace
