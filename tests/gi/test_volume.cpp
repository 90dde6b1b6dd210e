// The shared voxel volume (runtime/src/gi/volume.h) on lavapipe with validation on: 3D images,
// per-level state in the frame graph, the mip chain against the CPU's means, the used size of a
// cheaper level, and the shader passes' bind-by-name errors.
#include <glm/gtc/packing.hpp>

#include <cmath>
#include <cstring>

#include "gi/volume.h"
#include "gpu/frame_graph.h"
#include "vulkan/vk_test_util.h"

namespace {
using namespace mrgi;
using mrgi::test::VulkanTest;

constexpr uint32_t kRes = 8;

float value(uint32_t x, uint32_t y, uint32_t z, uint32_t c) {
  return 0.1f * float(x) + 0.37f * float(y * y) - 0.05f * float(z) + float(c) + 0.01f * float((x * 7 + y * 3 + z) % 5);
}

struct Fixture {
  std::unique_ptr<gpu::FrameGraph> graph;
  std::optional<gi::VoxelVolume> volume;
  gpu::BufferHandle readback;

  explicit Fixture(gpu::Context& ctx) {
    gpu::FrameGraphSettings fs;
    fs.max_output_width = 16;
    fs.max_output_height = 16;
    fs.frames_in_flight = 1;
    auto g = gpu::FrameGraph::create(ctx, fs);
    EXPECT_TRUE(g.ok()) << g.error().message;
    graph = std::move(*g);
    gi::VolumeSettings s;
    s.name = "test volume";
    s.resolution = kRes;
    s.mip_chain = true;
    auto v = gi::VoxelVolume::create(*graph, s);
    EXPECT_TRUE(v.ok()) << v.error().message;
    volume.emplace(std::move(*v));
    gpu::BufferDesc bd;
    bd.name = "levels readback";
    bd.size = kRes * kRes * kRes * 8 * 2;  // every level, RGBA16F, with room
    bd.memory = gpu::MemoryUsage::Readback;
    auto rb = graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(rb.ok()) << rb.error().message;
    readback = *rb;
    std::vector<uint16_t> texels(size_t(kRes) * kRes * kRes * 4);
    for (uint32_t z = 0; z < kRes; ++z)
      for (uint32_t y = 0; y < kRes; ++y)
        for (uint32_t x = 0; x < kRes; ++x)
          for (uint32_t c = 0; c < 4; ++c)
            texels[((size_t(z) * kRes + y) * kRes + x) * 4 + c] = uint16_t(glm::packHalf1x16(value(x, y, z, c)));
    EXPECT_TRUE(graph->upload_image(volume->image(0), texels.data(), texels.size() * 2).ok());
  }

  // Runs the chain and copies levels 1.. into the readback buffer, level after level. Returns the
  // texel offsets of each level.
  std::vector<size_t> run() {
    std::vector<size_t> offsets;
    EXPECT_TRUE(graph->begin_frame().ok());
    volume->add_mip_chain(*graph);
    const uint32_t levels = volume->used_levels();
    size_t texels = 0;
    for (uint32_t m = 1; m < levels; ++m) {
      offsets.push_back(texels);
      const VkExtent3D e = graph->extent3d(volume->image(0), m);
      texels += size_t(e.width) * e.height * e.depth;
    }
    const gpu::ImageHandle img = volume->image(0);
    graph->add_pass(
        "copy levels", gpu::PassKind::Transfer,
        [&](gpu::PassBuilder& b) {
          b.read(img, gpu::Access::TransferSrc, 1, levels - 1);
          b.write(readback, gpu::Access::TransferDst);
        },
        [this, img, levels, offsets](VkCommandBuffer cmd, gpu::PassContext& p) {
          for (uint32_t m = 1; m < levels; ++m) {
            VkBufferImageCopy r{};
            r.bufferOffset = offsets[m - 1] * 8;
            r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
            r.imageExtent = p.extent3d(img, m);
            vkCmdCopyImageToBuffer(cmd, p.image(img), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(readback), 1, &r);
          }
        });
    graph->mark_output(readback);
    EXPECT_TRUE(graph->compile().ok());
    EXPECT_TRUE(graph->compiled().culled.empty());
    EXPECT_TRUE(graph->submit().ok());
    auto done = graph->flush();
    EXPECT_TRUE(done.ok());
    return offsets;
  }

  glm::vec4 texel(size_t offset, const VkExtent3D& e, uint32_t x, uint32_t y, uint32_t z) const {
    const auto* h = static_cast<const uint16_t*>(graph->mapped(readback, 0));
    const size_t i = (offset + (size_t(z) * e.height + y) * e.width + x) * 4;
    return {glm::unpackHalf1x16(h[i]), glm::unpackHalf1x16(h[i + 1]), glm::unpackHalf1x16(h[i + 2]),
            glm::unpackHalf1x16(h[i + 3])};
  }
};

// The CPU's mean of level 0 over the cube of `size` cells at `corner`.
float mean(uint32_t x0, uint32_t y0, uint32_t z0, uint32_t size, uint32_t c) {
  double sum = 0.0;
  for (uint32_t z = z0; z < z0 + size; ++z)
    for (uint32_t y = y0; y < y0 + size; ++y)
      for (uint32_t x = x0; x < x0 + size; ++x) sum += glm::unpackHalf1x16(glm::packHalf1x16(value(x, y, z, c)));
  return float(sum / (double(size) * size * size));
}

TEST_F(VulkanTest, VolumeMipChainIsTheMeanOfEachBlock) {
  Fixture f(ctx());
  EXPECT_EQ(f.volume->allocated_levels(), 4u);  // 8, 4, 2, 1
  EXPECT_EQ(f.volume->used_levels(), 4u);
  const std::vector<size_t> offsets = f.run();
  for (uint32_t m = 1; m < 4; ++m) {
    const VkExtent3D e = f.graph->extent3d(f.volume->image(0), m);
    ASSERT_EQ(e.width, kRes >> m);
    const uint32_t block = 1u << m;
    for (uint32_t z = 0; z < e.depth; ++z)
      for (uint32_t y = 0; y < e.height; ++y)
        for (uint32_t x = 0; x < e.width; ++x)
          for (uint32_t c = 0; c < 4; ++c) {
            const float want = mean(x * block, y * block, z * block, block, c);
            // Half precision at every level (3 roundings of a value up to ~20): 0.03 absolute.
            EXPECT_NEAR(f.texel(offsets[m - 1], e, x, y, z)[c], want, 0.03f)
                << "level " << m << " cell " << x << "," << y << "," << z << " channel " << c;
          }
  }
}

TEST_F(VulkanTest, VolumeCheaperLevelUsesItsCornerOnly) {
  // Divisor 2: 4 cells per side used, a chain of 3 levels; the last is the mean of the used 4^3.
  Fixture f(ctx());
  ASSERT_TRUE(f.volume->set_divisor(*f.graph, 2).ok());
  EXPECT_EQ(f.volume->cells(), 4u);
  EXPECT_EQ(f.volume->used_levels(), 3u);
  const std::vector<size_t> offsets = f.run();
  ASSERT_EQ(offsets.size(), 2u);
  const VkExtent3D e = f.graph->extent3d(f.volume->image(0), 2);
  EXPECT_EQ(e.width, 1u);
  for (uint32_t c = 0; c < 4; ++c) EXPECT_NEAR(f.texel(offsets[1], e, 0, 0, 0)[c], mean(0, 0, 0, 4, c), 0.03f);
  EXPECT_EQ(f.volume->set_divisor(*f.graph, 8).error().kind, ErrorKind::BadUsage);  // 1 cell: too few
  ASSERT_TRUE(f.volume->set_divisor(*f.graph, 1).ok());
  EXPECT_EQ(f.volume->used_levels(), 4u);
}

TEST_F(VulkanTest, VolumeSettingsOutOfRangeAreRefusedByName) {
  auto g = gpu::FrameGraph::create(ctx(), gpu::FrameGraphSettings{});
  ASSERT_TRUE(g.ok());
  gi::VolumeSettings s;
  s.resolution = 1;
  auto v = gi::VoxelVolume::create(**g, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("VolumeSettings.resolution"), std::string::npos);
  s.resolution = 8;
  s.images = 5;
  v = gi::VoxelVolume::create(**g, s);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("VolumeSettings.images"), std::string::npos);
}

// Bind-by-name: the shader's declarations are the one list; what does not match them fails
// compile() naming the pass and the binding.
TEST_F(VulkanTest, ShaderPassBindingErrorsNameThePassAndBinding) {
  auto pipe = gpu::load_compute_pipeline(ctx(), "gi/volume_downsample.comp", {});
  ASSERT_TRUE(pipe.ok()) << pipe.error().message;
  // The layout came from the shader: two storage images, readonly and writeonly, 32 push bytes.
  const gpu::ShaderInterface& iface = (*pipe)->interface;
  ASSERT_EQ(iface.bindings.size(), 2u);
  EXPECT_EQ(iface.bindings[0].name, "finer");
  EXPECT_TRUE(iface.bindings[0].read);
  EXPECT_FALSE(iface.bindings[0].written);
  EXPECT_EQ(iface.bindings[1].name, "coarser");
  EXPECT_FALSE(iface.bindings[1].read);
  EXPECT_TRUE(iface.bindings[1].written);
  EXPECT_EQ((*pipe)->push_constant_bytes, 32u);
  // A frame whose compile() failed is not submitted: each attempt gets its own graph.
  std::optional<Fixture> f;
  gpu::ImageHandle img;
  auto try_compile = [&](const gpu::FrameGraph::ShaderSetupFn& setup) {
    f.emplace(ctx());
    img = f->volume->image(0);
    EXPECT_TRUE(f->graph->begin_frame().ok());
    f->graph->add_shader_pass("probe pass", gpu::PassKind::Compute, **pipe, setup, {});
    f->graph->mark_output(img);
    return f->graph->compile();
  };
  Status unknown = try_compile([&](gpu::ShaderPassBuilder& b) {
    b.bind("finer", img, 0);
    b.bind("coarse", img, 1);
  });
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(unknown.error().message.find("pass 'probe pass', binding 'coarse': not declared"), std::string::npos)
      << unknown.error().message;
  EXPECT_NE(unknown.error().message.find("finer, coarser"), std::string::npos) << unknown.error().message;
  Status unbound = try_compile([&](gpu::ShaderPassBuilder& b) { b.bind("finer", img, 0); });
  ASSERT_FALSE(unbound.ok());
  EXPECT_NE(unbound.error().message.find("'coarser' (binding 1) is not bound"), std::string::npos)
      << unbound.error().message;
  Status kind = try_compile([&](gpu::ShaderPassBuilder& b) {
    b.bind("finer", f->readback);
    b.bind("coarser", img, 1);
  });
  ASSERT_FALSE(kind.ok());
  EXPECT_NE(kind.error().message.find("declares a storage image, the pass binds a buffer"), std::string::npos)
      << kind.error().message;
  Status overlap = try_compile([&](gpu::ShaderPassBuilder& b) {
    b.bind("finer", img, 1);
    b.bind("coarser", img, 1);
  });
  ASSERT_FALSE(overlap.ok());
  EXPECT_NE(overlap.error().message.find("declared twice"), std::string::npos) << overlap.error().message;
}

// bind_over: a pass that writes part of an image over an earlier pass's write declares it
// read-write, so the earlier pass is kept; a plain bind of the writeonly image makes the earlier
// write dead (rewritten unread) and the graph culls it.
TEST_F(VulkanTest, ShaderPassBindOverKeepsTheEarlierWrite) {
  auto pipe = gpu::load_compute_pipeline(ctx(), "floor.comp", {});  // src_image readonly, dst_image writeonly
  ASSERT_TRUE(pipe.ok()) << pipe.error().message;
  for (const bool over : {false, true}) {
    Fixture f(ctx());
    auto image = [&](const char* name) {
      gpu::ImageDesc d;
      d.name = name;
      d.format = VK_FORMAT_R8G8B8A8_UNORM;
      return *f.graph->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
    };
    const gpu::ImageHandle src = image("src"), dst = image("dst");
    ASSERT_TRUE(f.graph->begin_frame().ok());
    f.graph->add_shader_pass("whole", gpu::PassKind::Compute, **pipe, [&](gpu::ShaderPassBuilder& b) {
      b.bind("src_image", src);
      b.bind("dst_image", dst);
    }, {});
    f.graph->add_shader_pass("tiles", gpu::PassKind::Compute, **pipe, [&](gpu::ShaderPassBuilder& b) {
      b.bind("src_image", src);
      if (over) {
        b.bind_over("dst_image", dst);
      } else {
        b.bind("dst_image", dst);
      }
    }, {});
    f.graph->mark_output(dst);
    Status s = f.graph->compile();
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(f.graph->compiled().runs("whole"), over) << (over ? "bind_over" : "bind");
    EXPECT_TRUE(f.graph->compiled().runs("tiles"));
  }
  // Only for what the shader writes.
  Fixture f(ctx());
  gpu::ImageDesc d;
  d.name = "img";
  const gpu::ImageHandle img = *f.graph->create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
  ASSERT_TRUE(f.graph->begin_frame().ok());
  f.graph->add_shader_pass("probe", gpu::PassKind::Compute, **pipe, [&](gpu::ShaderPassBuilder& b) {
    b.bind_over("src_image", img);
  }, {});
  Status s = f.graph->compile();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("bind_over is for storage images and buffers the shader writes"), std::string::npos)
      << s.error().message;
}

// Passes that push descriptors by hand check their names when the pipeline is made.
TEST_F(VulkanTest, RequireBindingsNamesTheMissingOne) {
  auto pipe = gpu::load_compute_pipeline(ctx(), "gi/volume_downsample.comp", {});
  ASSERT_TRUE(pipe.ok()) << pipe.error().message;
  EXPECT_TRUE(gpu::require_bindings(**pipe, "downsample", {"finer", "coarser"}).ok());
  Status s = gpu::require_bindings(**pipe, "downsample", {"finer", "finest"});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(s.error().message.find("pipeline 'downsample': its shaders declare no binding 'finest'"), std::string::npos)
      << s.error().message;
}

}  // namespace
