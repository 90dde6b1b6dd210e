// Shared by the Vulkan tests: one lavapipe context with validation (and synchronization
// validation) for the whole binary, and a fixture that fails a test on any validation message.
#pragma once
#include <gtest/gtest.h>

#include <memory>

#include "gpu/context.h"

namespace mrgi::test {

inline gpu::Context& vk_context() {
  static std::unique_ptr<gpu::Context> ctx = [] {
    DeviceSettings s;
    s.device = "llvmpipe";
    s.validate = true;
    auto c = gpu::Context::create(s);
    if (!c) {
      ADD_FAILURE() << "cannot create the lavapipe context: " << c.error().message;
      std::abort();
    }
    return std::move(*c);
  }();
  return *ctx;
}

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override { vk_context().clear_validation_messages(); }
  void TearDown() override {
    const auto messages = vk_context().validation_messages();
    for (const auto& m : messages) ADD_FAILURE() << m;
    EXPECT_EQ(messages.size(), 0u) << "validation messages (tests run with validation on)";
  }
  gpu::Context& ctx() { return vk_context(); }
};

}  // namespace mrgi::test
