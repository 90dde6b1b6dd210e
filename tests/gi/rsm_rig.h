// The reflective-shadow-map rig shared by the gi tests (test_rsm.cpp, test_vpl.cpp): a real
// floor from a synthetic G-buffer (y = 0 over x, z in [0.5, 1.5], albedo 0.5), a virtual box
// (perf/suite/assets/white_box.gltf, 0.15 m tall, albedo 0.8) on it, the maps and an 8^3 volume.
#pragma once
#include <glm/gtc/packing.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gi/light_propagation.h"
#include "gi/rsm.h"
#include "frame/scene_gpu.h"
#include "vulkan/vk_test_util.h"

namespace mrgi::test {

constexpr uint32_t kG = 32;    // real G-buffer side
constexpr uint32_t kMap = 64;  // RSM side
inline const glm::vec3 kCentre(1.0f, 0.1f, 1.0f);
constexpr float kRadius = 0.5f;

struct RsmRig {
  std::unique_ptr<gpu::FrameGraph> graph;
  std::unique_ptr<frame::SceneGpu> scene;
  SceneDesc desc;
  gi::RealGBuffer real;
  std::optional<gi::ReflectiveShadowMaps> rsm;
  std::optional<gi::LightPropagationVolume> lpv;
  gpu::BufferHandle readback;

  explicit RsmRig(gpu::Context& ctx) {
    gpu::FrameGraphSettings fs;
    fs.max_output_width = fs.max_output_height = kG;
    fs.frames_in_flight = 1;
    auto g = gpu::FrameGraph::create(ctx, fs);
    EXPECT_TRUE(g.ok());
    graph = std::move(*g);
    desc.path = "rsm test scene";
    VirtualObjectDesc box;
    box.gltf = std::string(MRGI_SOURCE_DIR) + "/perf/suite/assets/white_box.gltf";
    box.placement.position = glm::vec3(1.0f, 0.0f, 1.0f);
    desc.virtual_objects.push_back(box);
    auto s = frame::SceneGpu::create(ctx, *graph, desc);
    EXPECT_TRUE(s.ok()) << s.error().message;
    scene = std::move(*s);
    // The floor y = 0 over x, z in [0.5, 1.5], seen from above, albedo 0.5.
    auto image = [&](const char* name, VkFormat f) {
      gpu::ImageDesc d;
      d.name = name;
      d.format = f;
      d.size_mode = gpu::SizeMode::Absolute;
      d.width = d.height = kG;
      return *graph->create_image(d, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    };
    real = {image("real position", VK_FORMAT_R32G32B32A32_SFLOAT), image("real normal", VK_FORMAT_R16G16B16A16_SFLOAT),
            image("real albedo", VK_FORMAT_R16G16B16A16_SFLOAT)};
    std::vector<float> pos;
    std::vector<uint16_t> nor, alb;
    for (uint32_t y = 0; y < kG; ++y)
      for (uint32_t x = 0; x < kG; ++x) {
        pos.insert(pos.end(), {0.5f + float(x) / float(kG - 1), 0.0f, 0.5f + float(y) / float(kG - 1), 1.5f});
        for (float c : {0.0f, 1.0f, 0.0f, 0.0f}) nor.push_back(uint16_t(glm::packHalf1x16(c)));
        for (float c : {0.5f, 0.5f, 0.5f, 1.0f}) alb.push_back(uint16_t(glm::packHalf1x16(c)));
      }
    EXPECT_TRUE(graph->upload_image(real.position, pos.data(), pos.size() * 4).ok());
    EXPECT_TRUE(graph->upload_image(real.normal, nor.data(), nor.size() * 2).ok());
    EXPECT_TRUE(graph->upload_image(real.albedo, alb.data(), alb.size() * 2).ok());
    gi::RsmSettings rs;
    rs.size = kMap;
    auto r = gi::ReflectiveShadowMaps::create(*graph, *scene, real, rs);
    EXPECT_TRUE(r.ok()) << r.error().message;
    rsm.emplace(std::move(*r));
    gi::LpvSettings ls;
    ls.resolution = 8;
    auto l = gi::LightPropagationVolume::create(*graph, ls);
    EXPECT_TRUE(l.ok()) << l.error().message;
    lpv.emplace(std::move(*l));
    lpv->set_grid({kCentre - glm::vec3(kRadius), 2.0f * kRadius / 8.0f});
    gpu::BufferDesc bd;
    bd.name = "rsm readback";
    bd.size = VkDeviceSize(kMap) * kMap * 16 * 4 + 8 * 8 * 8 * 16;
    bd.memory = gpu::MemoryUsage::Readback;
    readback = *graph->create_buffer(bd, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  }
};

inline LightDesc sun() {
  LightDesc l;
  l.type = LightType::Directional;
  l.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  l.intensity = 2.0f;
  return l;
}

}  // namespace mrgi::test
