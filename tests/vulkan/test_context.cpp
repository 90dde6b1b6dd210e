// The Vulkan context on lavapipe: creation with validation, device selection rules, memory
// accounting and start-up uploads.
#include <cstdlib>
#include <cstring>

#include "gpu/vk_check.h"
#include "vk_test_util.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

std::vector<DeviceInfo> fake_devices() {
  std::vector<DeviceInfo> d(3);
  d[0] = {0, "AMD Radeon RX 6600", "discrete-gpu", "radv", VK_API_VERSION_1_3, 8192, false};
  d[1] = {1, "llvmpipe (LLVM 15.0.6, 256 bits)", "cpu", "llvmpipe", VK_API_VERSION_1_3, 0, false};
  d[2] = {2, "Intel(R) UHD Graphics 620", "integrated-gpu", "anv", VK_API_VERSION_1_3, 0, false};
  return d;
}

TEST(DeviceSelection, EmptySelectorPrefersLavapipe) {
  auto i = select_device_index(fake_devices(), "");
  ASSERT_TRUE(i.ok());
  EXPECT_EQ(*i, 1u);
}

TEST(DeviceSelection, EmptySelectorWithoutLavapipeTakesDeviceZero) {
  auto d = fake_devices();
  d.erase(d.begin() + 1);
  auto i = select_device_index(d, "");
  ASSERT_TRUE(i.ok());
  EXPECT_EQ(*i, 0u);
}

TEST(DeviceSelection, NumberIsIndexTextIsNameSubstring) {
  EXPECT_EQ(*select_device_index(fake_devices(), "2"), 2u);
  EXPECT_EQ(*select_device_index(fake_devices(), "0"), 0u);
  EXPECT_EQ(*select_device_index(fake_devices(), "radeon"), 0u);  // case-insensitive
  EXPECT_EQ(*select_device_index(fake_devices(), "UHD"), 2u);
}

TEST(DeviceSelection, KindAliasesPickByDeviceType) {
  // lavapipe names itself "llvmpipe (LLVM ...)": its documented name must still select it.
  EXPECT_EQ(*select_device_index(fake_devices(), "lavapipe"), 1u);
  EXPECT_EQ(*select_device_index(fake_devices(), "LLVMpipe"), 1u);
  EXPECT_EQ(*select_device_index(fake_devices(), "cpu"), 1u);
  EXPECT_EQ(*select_device_index(fake_devices(), "gpu"), 0u) << "discrete before integrated";
  auto integrated_only = fake_devices();
  integrated_only.erase(integrated_only.begin());
  EXPECT_EQ(*select_device_index(integrated_only, "GPU"), 2u);
  auto no_gpu = select_device_index({fake_devices()[1]}, "gpu");
  ASSERT_FALSE(no_gpu.ok());
  EXPECT_EQ(no_gpu.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(no_gpu.error().message.find("no GPU device"), std::string::npos) << no_gpu.error().message;
  auto no_cpu = select_device_index({fake_devices()[0]}, "lavapipe");
  ASSERT_FALSE(no_cpu.ok());
  EXPECT_NE(no_cpu.error().message.find("0: AMD"), std::string::npos) << no_cpu.error().message;
}

TEST(DeviceSelection, UnmatchedSelectorIsBadUsageListingDevices) {
  auto bad_name = select_device_index(fake_devices(), "geforce");
  ASSERT_FALSE(bad_name.ok());
  EXPECT_EQ(bad_name.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(bad_name.error().message.find("geforce"), std::string::npos);
  EXPECT_NE(bad_name.error().message.find("1: llvmpipe"), std::string::npos) << bad_name.error().message;
  EXPECT_NE(bad_name.error().message.find("2: Intel"), std::string::npos);
  auto bad_index = select_device_index(fake_devices(), "3");
  ASSERT_FALSE(bad_index.ok());
  EXPECT_EQ(bad_index.error().kind, ErrorKind::BadUsage);
  auto huge = select_device_index(fake_devices(), "99999999999999999999");
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().kind, ErrorKind::BadUsage);
  EXPECT_EQ(select_device_index({}, "").error().kind, ErrorKind::NotFound);
}

TEST(DeviceSelection, EnvironmentVariableAppliesOnlyWhenSettingIsEmpty) {
  const char* old = std::getenv("MRGI_DEVICE");
  const std::string saved = old ? old : "";
  setenv("MRGI_DEVICE", "1", 1);
  EXPECT_EQ(effective_device_selector(DeviceSettings{}), "1");
  DeviceSettings explicit_setting;
  explicit_setting.device = "radeon";
  EXPECT_EQ(effective_device_selector(explicit_setting), "radeon");
  unsetenv("MRGI_DEVICE");
  EXPECT_EQ(effective_device_selector(DeviceSettings{}), "");
  if (old) setenv("MRGI_DEVICE", saved.c_str(), 1);
}

TEST(DeviceSelection, ListDevicesMarksLavapipe) {
  DeviceSettings s;
  s.device = "llvmpipe";
  auto devices = list_devices(s);
  ASSERT_TRUE(devices.ok()) << devices.error().message;
  int selected = 0;
  for (const auto& d : *devices) {
    if (!d.selected) continue;
    ++selected;
    EXPECT_NE(d.name.find("llvmpipe"), std::string::npos);
    EXPECT_EQ(d.type, "cpu");
    EXPECT_GE(d.api_version, VK_API_VERSION_1_2);
    EXPECT_NE(d.driver.find("llvmpipe"), std::string::npos) << d.driver;
  }
  EXPECT_EQ(selected, 1);
  s.device = "no-such-gpu";
  auto bad = list_devices(s);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(bad.error().message.find("llvmpipe"), std::string::npos);
}

TEST(ContextCreation, BadSelectorFailsCreation) {
  DeviceSettings s;
  s.device = "no-such-gpu";
  auto c = Context::create(s);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().kind, ErrorKind::BadUsage);
}

TEST(VkCheck, ErrorNamesFileLineExpressionAndResult) {
  auto f = []() -> Status {
    VK_CHECK(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    return ok_status();
  };
  Status s = f();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().kind, ErrorKind::Device);
  EXPECT_NE(s.error().message.find("test_context.cpp:"), std::string::npos);
  EXPECT_NE(s.error().message.find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos);
  EXPECT_TRUE(VK_STATUS(VK_SUCCESS).ok());
  EXPECT_STREQ(vk_result_name(VkResult(-12345)), "VkResult(-12345)");
}

TEST_F(VulkanTest, LavapipeContextWithValidation) {
  EXPECT_TRUE(ctx().validation_enabled());
  EXPECT_NE(ctx().info().name.find("llvmpipe"), std::string::npos);
  EXPECT_TRUE(ctx().info().selected);
  EXPECT_GT(ctx().timestamp_valid_bits(), 0u);
  EXPECT_GT(ctx().timestamp_period_ns(), 0.0);
  EXPECT_NE(ctx().cmd_push_descriptor_set(), nullptr);
  EXPECT_NE(ctx().fn().cmd_pipeline_barrier2, nullptr);
  EXPECT_NE(ctx().fn().cmd_begin_rendering, nullptr);
}

// The messenger is live: a deliberate misuse is recorded (then cleared so the fixture passes).
TEST_F(VulkanTest, ValidationMessagesAreRecorded) {
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = 0;  // invalid: size must be > 0
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer b = VK_NULL_HANDLE;
  const VkResult r = vkCreateBuffer(ctx().device(), &bci, nullptr, &b);
  if (r == VK_SUCCESS && b) vkDestroyBuffer(ctx().device(), b, nullptr);
  EXPECT_GE(ctx().validation_message_count(), 1u);
  ctx().clear_validation_messages();
}

TEST_F(VulkanTest, MemoryAccountingIsExact) {
  const uint64_t before = ctx().allocated_bytes();
  const uint64_t count = ctx().allocation_count();
  auto b = ctx().create_buffer(1000, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal, "t");
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_GE(b->allocated, 1000u);
  EXPECT_EQ(ctx().allocated_bytes(), before + b->allocated);
  ImageCreateDesc d;
  d.width = 64;
  d.height = 32;
  d.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  d.usage = VK_IMAGE_USAGE_STORAGE_BIT;
  d.name = "t-img";
  auto img = ctx().create_image(d);
  ASSERT_TRUE(img.ok()) << img.error().message;
  EXPECT_GE(img->allocated, 64u * 32u * 8u);
  EXPECT_EQ(ctx().allocated_bytes(), before + b->allocated + img->allocated);
  EXPECT_EQ(ctx().allocation_count(), count + 2);
  ctx().destroy(*b);
  ctx().destroy(*img);
  EXPECT_EQ(ctx().allocated_bytes(), before);
  EXPECT_EQ(ctx().allocation_count(), count);
}

TEST_F(VulkanTest, BadResourceRequestsAreErrors) {
  auto b = ctx().create_buffer(0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal, "zero");
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().kind, ErrorKind::BadUsage);
  ImageCreateDesc d;
  d.width = 1u << 20;
  d.height = 4;
  d.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  d.name = "huge";
  auto img = ctx().create_image(d);
  ASSERT_FALSE(img.ok());
  EXPECT_NE(img.error().message.find("huge"), std::string::npos);
}

TEST_F(VulkanTest, UploadBufferAndReadBack) {
  auto dev = ctx().create_buffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                 MemoryUsage::DeviceLocal, "dev");
  auto rb = ctx().create_buffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::Readback, "rb");
  ASSERT_TRUE(dev.ok() && rb.ok());
  std::vector<uint8_t> bytes(256);
  for (int i = 0; i < 256; ++i) bytes[i] = uint8_t(i * 7);
  ASSERT_TRUE(ctx().upload_buffer(*dev, bytes.data(), bytes.size()).ok());
  Status s = ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy c{0, 0, 256};
    vkCmdCopyBuffer(cmd, dev->buffer, rb->buffer, 1, &c);
    VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    mb.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
    mb.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    mb.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    mb.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    di.memoryBarrierCount = 1;
    di.pMemoryBarriers = &mb;
    ctx().fn().cmd_pipeline_barrier2(cmd, &di);
  });
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE(ctx().invalidate(*rb).ok());
  EXPECT_EQ(std::memcmp(rb->mapped, bytes.data(), 256), 0);
  auto too_big = ctx().upload_buffer(*dev, bytes.data(), 300);
  EXPECT_FALSE(too_big.ok());
  ctx().destroy(*dev);
  ctx().destroy(*rb);
}

}  // namespace
