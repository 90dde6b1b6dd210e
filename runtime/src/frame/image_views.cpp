#include "frame/image_views.h"

#include "gpu/vk_check.h"

namespace mrgi::frame {

Expected<VkImageView> ImageViews::create(const gpu::GpuImage& image, VkImageViewType type,
                                         uint32_t base, uint32_t count) {
  if (base + count > image.layers || count == 0)
    return fail(ErrorKind::Internal, "image view: layers [" + std::to_string(base) + ", " +
                                         std::to_string(base + count) + ") outside the image's " +
                                         std::to_string(image.layers));
  VkImageViewCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  ci.image = image.image;
  ci.viewType = type;
  ci.format = image.format;
  ci.subresourceRange = {image.aspect, 0, image.mip_levels, base, count};
  VkImageView view = VK_NULL_HANDLE;
  VK_CHECK(vkCreateImageView(device_, &ci, nullptr, &view));
  views_.push_back(view);
  return view;
}

void ImageViews::reset() {
  for (VkImageView v : views_) vkDestroyImageView(device_, v, nullptr);
  views_.clear();
}

}  // namespace mrgi::frame
