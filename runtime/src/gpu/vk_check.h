// Vulkan results as mrgi errors. Every Vulkan call whose result can fail goes through VK_CHECK so
// a failure names the file, the line, the call and the VkResult instead of being dropped.
#pragma once
#include <vulkan/vulkan.h>

#include <string>

#include "mrgi/expected.h"

namespace mrgi::gpu {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; "VkResult(<n>)" for values this build does not know.
const char* vk_result_name(VkResult result);

// Error{Device, "<file>:<line>: <expr> failed with <VkResult name>"}.
Error vk_error(VkResult result, const char* expr, const char* file, int line);

// Status of one Vulkan call, for places that cannot `return` (lambdas collecting errors).
inline Status vk_status(VkResult result, const char* expr, const char* file, int line) {
  if (result == VK_SUCCESS) return ok_status();
  return vk_error(result, expr, file, line);
}

}  // namespace mrgi::gpu

// Inside a function returning Expected<T> or Status: returns the error when `expr` is not
// VK_SUCCESS (VK_INCOMPLETE, VK_TIMEOUT, VK_NOT_READY are failures here too: call sites that
// expect them test the result themselves).
#define VK_CHECK(expr)                                                                   \
  do {                                                                                   \
    const VkResult mrgi_vk_result_ = (expr);                                             \
    if (mrgi_vk_result_ != VK_SUCCESS)                                                   \
      return ::mrgi::gpu::vk_error(mrgi_vk_result_, #expr, __FILE__, __LINE__);          \
  } while (0)

// The same check as an expression yielding Status (for use with MRGI_TRY or to collect errors).
#define VK_STATUS(expr) ::mrgi::gpu::vk_status((expr), #expr, __FILE__, __LINE__)
