// Extra views of graph images: a 2D-array view of an image of any layer count (the context
// makes single-layer images' views 2D, but array samplers need an array view), and single-layer
// views to render into one layer of a layered depth map. Created at start-up, destroyed with
// the owner.
#pragma once
#include <vulkan/vulkan.h>

#include <vector>

#include "gpu/context.h"
#include "mrgi/expected.h"

namespace mrgi::frame {

class ImageViews {
 public:
  ImageViews() = default;
  explicit ImageViews(VkDevice device) : device_(device) {}
  ~ImageViews() { reset(); }
  ImageViews(ImageViews&& o) noexcept : device_(o.device_), views_(std::move(o.views_)) { o.views_.clear(); }
  ImageViews& operator=(ImageViews&& o) noexcept {
    if (this != &o) { reset(); device_ = o.device_; views_ = std::move(o.views_); o.views_.clear(); }
    return *this;
  }
  ImageViews(const ImageViews&) = delete;
  ImageViews& operator=(const ImageViews&) = delete;

  // A view of layers [base, base + count) of `image`, of `type` (2D or 2D_ARRAY).
  Expected<VkImageView> create(const gpu::GpuImage& image, VkImageViewType type, uint32_t base,
                               uint32_t count);
  void reset();

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  std::vector<VkImageView> views_;
};

}  // namespace mrgi::frame
