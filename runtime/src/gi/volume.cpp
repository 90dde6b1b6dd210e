#include "gi/volume.h"

#include <string>

namespace mrgi::gi {
namespace {

Error volume_setting_error(const std::string& field, const std::string& rule) {
  return fail(ErrorKind::BadUsage, "VolumeSettings." + field + ": " + rule);
}

struct DownsamplePush {
  int32_t finer[4];
  int32_t coarser[4];
};

}  // namespace

Expected<VoxelVolume> VoxelVolume::create(gpu::FrameGraph& graph, const VolumeSettings& s) {
  if (s.resolution < 2 || s.resolution > 256) return volume_setting_error("resolution", "must be 2..256 cells");
  if (s.images < 1 || s.images > 4) return volume_setting_error("images", "must be 1..4");
  if (s.name.empty()) return volume_setting_error("name", "must not be empty");
  if (s.format != VK_FORMAT_R16G16B16A16_SFLOAT && s.format != VK_FORMAT_R32G32B32A32_SFLOAT)
    return volume_setting_error("format", "must be RGBA16F or RGBA32F");
  if (s.mip_chain && s.format != VK_FORMAT_R16G16B16A16_SFLOAT)
    return fail(ErrorKind::NotImplemented, "VolumeSettings.mip_chain: RGBA32F volumes have no mip-chain shader yet");
  VoxelVolume v;
  v.settings_ = s;
  if (s.mip_chain)
    while ((s.resolution >> v.levels_) > 0) ++v.levels_;
  for (uint32_t i = 0; i < s.images; ++i) {
    gpu::ImageDesc d;
    d.name = s.images == 1 ? s.name : s.name + "[" + std::to_string(i) + "]";
    d.format = s.format;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = d.height = d.depth = s.resolution;
    d.mip_levels = v.levels_;
    d.history = s.history;
    auto h = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                       VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    if (!h) return h.error();
    v.images_[i] = *h;
  }
  if (s.mip_chain) {
    auto p = gpu::load_compute_pipeline(graph.context(), "gi/volume_downsample.comp", {});
    if (!p) return p.error();
    v.downsample_ = std::move(*p);
  }
  return v;
}

Status VoxelVolume::set_divisor(gpu::FrameGraph& graph, uint32_t divisor) {
  if (divisor < 1 || settings_.resolution / divisor < 2)
    return fail(ErrorKind::BadUsage, "volume '" + settings_.name + "': divisor " + std::to_string(divisor) +
                                         " must be >= 1 and leave at least 2 of its " +
                                         std::to_string(settings_.resolution) + " cells per side");
  for (uint32_t i = 0; i < settings_.images; ++i) MRGI_TRY(graph.set_extent_divisor(images_[i], divisor));
  divisor_ = divisor;
  return ok_status();
}

uint32_t VoxelVolume::used_levels() const {
  if (!settings_.mip_chain) return 1;
  uint32_t n = 1;
  while ((cells() >> n) > 0 && n < levels_) ++n;
  return n;
}

void VoxelVolume::add_clear(gpu::FrameGraph& graph) const {
  graph.add_pass(
      settings_.name + " clear", gpu::PassKind::Transfer,
      [this](gpu::PassBuilder& b) {
        for (uint32_t i = 0; i < settings_.images; ++i) b.write(images_[i], gpu::Access::TransferDst);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& p) {
        const VkClearColorValue zero{};
        const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, levels_, 0, 1};
        for (uint32_t i = 0; i < settings_.images; ++i)
          vkCmdClearColorImage(cmd, p.image(images_[i]), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &all);
      });
}

Status VoxelVolume::set_cells(gpu::FrameGraph& graph, uint32_t cells, const std::string& what) {
  if (cells < 2 || cells > settings_.resolution || settings_.resolution % cells != 0)
    return fail(ErrorKind::BadUsage, what + " '" + settings_.name + "': " + std::to_string(cells) +
                                         " cells per side: must divide the allocated " +
                                         std::to_string(settings_.resolution) + " and be at least 2");
  return set_divisor(graph, settings_.resolution / cells);
}

void VoxelVolume::add_clear_if_resized(gpu::FrameGraph& graph) {
  if (cleared_cells_ == cells()) return;
  add_clear(graph);
  cleared_cells_ = cells();
  clear_pending_ = true;
}

void VoxelVolume::keep_cleared_margin(gpu::ShaderPassBuilder& b) {
  if (!clear_pending_) return;
  clear_pending_ = false;
  if (levels_ > 1)
    for (uint32_t i = 0; i < settings_.images; ++i) b.uses().read(images_[i], gpu::Access::StorageRead, 1, levels_ - 1);
}

void VoxelVolume::add_mip_chain(gpu::FrameGraph& graph) const {
  const uint32_t levels = used_levels();
  for (uint32_t m = 1; m < levels; ++m) {
    for (uint32_t i = 0; i < settings_.images; ++i) {
      const gpu::ImageHandle img = images_[i];
      graph.add_shader_pass(
          graph.name(img) + " mip " + std::to_string(m), gpu::PassKind::Compute, *downsample_,
          [img, m](gpu::ShaderPassBuilder& b) {
            b.bind("finer", img, m - 1);
            b.bind("coarser", img, m);
          },
          [this, img, m](VkCommandBuffer cmd, gpu::PassContext& p) {
            const VkExtent3D f = p.extent3d(img, m - 1), c = p.extent3d(img, m);
            const DownsamplePush push{{int32_t(f.width), int32_t(f.height), int32_t(f.depth), 0},
                                      {int32_t(c.width), int32_t(c.height), int32_t(c.depth), 0}};
            gpu::push_and_dispatch(cmd, *downsample_, &push, sizeof push, {(c.width + 3) / 4, (c.height + 3) / 4, (c.depth + 3) / 4});
          });
    }
  }
}

}  // namespace mrgi::gi
