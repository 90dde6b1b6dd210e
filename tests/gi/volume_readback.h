// Test helper for the voxel blocks (gi/voxelize.h, gi/voxel_light.h): one frame of passes that
// fill a volume, then its finest levels read back as RGBA floats.
#pragma once
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <vector>

#include "gpu/frame_graph.h"

namespace mrgi::test {

// A frame graph for a block test: one frame in flight, a 16 x 16 output (the blocks' images are
// sized absolutely).
inline std::unique_ptr<gpu::FrameGraph> make_block_graph(gpu::Context& ctx) {
  gpu::FrameGraphSettings fs;
  fs.max_output_width = fs.max_output_height = 16;
  fs.frames_in_flight = 1;
  auto g = gpu::FrameGraph::create(ctx, fs);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.error().message);
  return g.ok() ? std::move(*g) : nullptr;
}

// Readback space for levels 0 and 1 of an RGBA16F volume of n^3 cells.
inline gpu::BufferHandle make_volume_readback(gpu::FrameGraph& graph, uint32_t n) {
  gpu::BufferDesc bd;
  bd.name = "volume readback";
  bd.size = VkDeviceSize(n) * n * n * 8 * 2;
  bd.memory = gpu::MemoryUsage::Readback;
  return *graph.create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
}

// One frame: `add` records the passes that fill `image` (an RGBA16F volume of n^3 cells with a
// mip chain), then levels 0 and 1 are copied out; returns them, [level][(z n + y) n + x].
inline std::vector<std::vector<glm::vec4>> run_and_read_volume(gpu::FrameGraph& graph, gpu::ImageHandle image,
                                                               gpu::BufferHandle readback, uint32_t n,
                                                               const std::function<void()>& add) {
  EXPECT_TRUE(graph.begin_frame().ok());
  add();
  graph.add_pass(
      "copy volume", gpu::PassKind::Transfer,
      [&](gpu::PassBuilder& b) {
        b.read(image, gpu::Access::TransferSrc);
        b.write(readback, gpu::Access::TransferDst);
      },
      [image, readback, n](VkCommandBuffer cmd, gpu::PassContext& p) {
        VkBufferImageCopy r[2]{};
        for (uint32_t level = 0; level < 2; ++level) {
          const uint32_t m = n >> level;
          r[level].bufferOffset = level == 0 ? 0 : VkDeviceSize(n) * n * n * 8;
          r[level].imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 1};
          r[level].imageExtent = {m, m, m};
        }
        vkCmdCopyImageToBuffer(cmd, p.image(image), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.buffer(readback), 2, r);
      });
  graph.mark_output(readback);
  Status s = graph.compile();
  EXPECT_TRUE(s.ok()) << s.error().message;
  EXPECT_TRUE(graph.submit().ok());
  EXPECT_TRUE(graph.flush().ok());
  const auto* halfs = static_cast<const uint16_t*>(graph.mapped(readback, 0));
  std::vector<std::vector<glm::vec4>> out(2);
  for (uint32_t level = 0; level < 2; ++level) {
    const uint32_t m = n >> level;
    const uint16_t* h = halfs + (level == 0 ? 0 : size_t(n) * n * n * 4);
    for (size_t i = 0; i < size_t(m) * m * m; ++i)
      out[level].push_back(glm::vec4(glm::unpackHalf1x16(h[4 * i]), glm::unpackHalf1x16(h[4 * i + 1]),
                                     glm::unpackHalf1x16(h[4 * i + 2]), glm::unpackHalf1x16(h[4 * i + 3])));
  }
  return out;
}

}  // namespace mrgi::test
