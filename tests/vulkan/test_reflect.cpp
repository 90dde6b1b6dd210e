// SPIR-V reflection (gpu/reflect.h): a shader's declarations are the source of its pipeline
// layout, and a hand-written list that disagrees is refused at start-up naming both sides.
#include <gtest/gtest.h>

#include "gpu/pipelines.h"
#include "gpu/reflect.h"
#include "gpu/shaders.h"
#include "vk_test_util.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

TEST(Reflect, FloorShaderDeclaresTwoImagesAndEightPushBytes) {
  auto spirv = shader_spirv("floor.comp");
  ASSERT_TRUE(spirv.ok());
  auto iface = reflect_shader(*spirv, "floor.comp");
  ASSERT_TRUE(iface.ok()) << iface.error().message;
  ASSERT_EQ(iface->bindings.size(), 2u);
  EXPECT_EQ(iface->bindings[0], (ShaderBinding{"src_image", 0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, true, false}));
  EXPECT_EQ(iface->bindings[1], (ShaderBinding{"dst_image", 1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, false, true}));
  EXPECT_EQ(iface->push_constant_bytes, 8u);
  EXPECT_EQ(iface->find("dst_image"), &iface->bindings[1]);
  EXPECT_EQ(iface->find("nothing"), nullptr);
}

TEST(Reflect, EveryEmbeddedShaderReflects) {
  for (const std::string& name : shader_names()) {
    auto spirv = shader_spirv(name);
    ASSERT_TRUE(spirv.ok()) << name;
    auto iface = reflect_shader(*spirv, name);
    EXPECT_TRUE(iface.ok()) << name << ": " << (iface.ok() ? "" : iface.error().message);
  }
}

TEST(Reflect, GarbageIsRefusedNotCrashed) {
  const std::vector<uint32_t> junk = {0x07230203u, 0x00010000u, 0u, 5u, 0u, 0xdeadbeefu};
  auto iface = reflect_shader(junk, "junk.comp");
  ASSERT_FALSE(iface.ok());
  EXPECT_EQ(iface.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(iface.error().message.find("junk.comp"), std::string::npos);
}

TEST_F(VulkanTest, HandWrittenBindingsThatDisagreeWithTheShaderAreRefused) {
  auto spirv = shader_spirv("floor.comp");
  ASSERT_TRUE(spirv.ok());
  ComputePipelineDesc d;
  d.name = "floor";
  d.spirv = *spirv;
  d.push_constant_bytes = 8;
  d.bindings = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
  auto p = create_compute_pipeline(ctx(), d);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("binding 0 is a storage buffer x1 here and a storage image 'src_image' x1 in the shader"),
            std::string::npos)
      << p.error().message;
  d.bindings = {{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
  p = create_compute_pipeline(ctx(), d);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("'dst_image' (binding 1) is missing here"), std::string::npos) << p.error().message;
  d.bindings = {};
  d.push_constant_bytes = 4;
  p = create_compute_pipeline(ctx(), d);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("4 bytes of push constants, the shader declares 8"), std::string::npos)
      << p.error().message;
  // No list at all: the shader's own layout and push-constant size.
  d.push_constant_bytes = 0;
  p = create_compute_pipeline(ctx(), d);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->push_constant_bytes, 8u);
  EXPECT_EQ(p->interface.bindings.size(), 2u);
  destroy_pipeline(ctx(), *p);
}

}  // namespace
