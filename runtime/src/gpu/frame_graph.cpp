// The runtime half of the frame graph: resources, frame slots, recording and timestamps. The
// culling and barrier rules are in frame_graph_compile.cpp, submission (normal and profiling
// mode) in frame_graph_submit.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <string>

#include "gpu/frame_graph.h"
#include "gpu/frame_graph_entries.h"
#include "gpu/vk_check.h"

namespace mrgi::gpu {

double process_cpu_ms() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// --- PassBuilder / PassContext -------------------------------------------------------------------

void PassBuilder::read(ImageHandle image, Access access) {
  decl_.uses.push_back({ResourceRef{true, image.id}, access});
}
void PassBuilder::write(ImageHandle image, Access access) {
  decl_.uses.push_back({ResourceRef{true, image.id}, access});
}
void PassBuilder::read(ImageHandle image, Access access, uint32_t base_mip, uint32_t mip_count) {
  decl_.uses.push_back({ResourceRef{true, image.id}, access, base_mip, mip_count});
}
void PassBuilder::write(ImageHandle image, Access access, uint32_t base_mip, uint32_t mip_count) {
  decl_.uses.push_back({ResourceRef{true, image.id}, access, base_mip, mip_count});
}
void PassBuilder::read(BufferHandle buffer, Access access) {
  decl_.uses.push_back({ResourceRef{false, uint32_t(graph_.images_.size()) + buffer.id}, access});
}
void PassBuilder::write(BufferHandle buffer, Access access) {
  decl_.uses.push_back({ResourceRef{false, uint32_t(graph_.images_.size()) + buffer.id}, access});
}
void PassBuilder::side_effect() { decl_.side_effect = true; }

VkImage PassContext::image(ImageHandle h) const { return graph_.gpu_image(h).image; }
VkImageView PassContext::view(ImageHandle h) const { return graph_.gpu_image(h).view; }
VkImageView PassContext::view(ImageHandle h, uint32_t mip) const {
  const GpuImage& img = graph_.gpu_image(h);
  return img.mip_levels == 1 && mip == 0 ? img.view : img.mip_views.at(mip);
}
VkExtent3D PassContext::extent3d(ImageHandle h, uint32_t mip) const { return graph_.extent3d(h, mip); }
VkFormat PassContext::format(ImageHandle h) const { return graph_.gpu_image(h).format; }
VkExtent2D PassContext::extent(ImageHandle h) const { return graph_.extent(h); }
VkBuffer PassContext::buffer(BufferHandle h) const { return graph_.gpu_buffer(h, graph_.slot_).buffer; }
VkBufferView PassContext::texel_view(BufferHandle h) const {
  return graph_.gpu_buffer(h, graph_.slot_).texel_view;
}
VkDeviceSize PassContext::buffer_size(BufferHandle h) const { return graph_.gpu_buffer(h, graph_.slot_).size; }
void* PassContext::mapped(BufferHandle h) const { return graph_.mapped(h, graph_.slot_); }
VkExtent2D PassContext::output_size() const { return graph_.output_size_; }
float PassContext::render_scale() const { return graph_.render_scale_; }
int64_t PassContext::frame_index() const { return graph_.frame_index_; }
uint32_t PassContext::slot() const { return graph_.slot_; }
const Context& PassContext::context() const { return graph_.context_; }

// --- creation ------------------------------------------------------------------------------------

FrameGraph::FrameGraph(Context& context, const FrameGraphSettings& settings)
    : context_(context), settings_(settings) {}

Expected<std::unique_ptr<FrameGraph>> FrameGraph::create(Context& context, const FrameGraphSettings& settings) {
  if (settings.frames_in_flight < 1 || settings.frames_in_flight > 3)
    return fail(ErrorKind::BadUsage, "FrameGraphSettings.frames_in_flight = " +
                                         std::to_string(settings.frames_in_flight) + ": must be 1..3");
  if (settings.max_output_width == 0 || settings.max_output_height == 0)
    return fail(ErrorKind::BadUsage, "FrameGraphSettings.max_output_width/height must be > 0");
  if (!(settings.max_render_scale > 0.0f && settings.max_render_scale <= 1.0f))
    return fail(ErrorKind::BadUsage, "FrameGraphSettings.max_render_scale must be in (0, 1]");
  if (settings.max_passes == 0 || settings.max_passes > 1024)
    return fail(ErrorKind::BadUsage, "FrameGraphSettings.max_passes must be 1..1024");
  if (context.timestamp_valid_bits() == 0)
    return fail(ErrorKind::Device, "device '" + context.info().name + "': its queue has no timestamps, "
                                   "which per-pass timing needs");
  std::unique_ptr<FrameGraph> g(new FrameGraph(context, settings));
  MRGI_TRY(g->init());
  return g;
}

Status FrameGraph::init() {
  output_size_ = {settings_.max_output_width, settings_.max_output_height};
  render_scale_ = settings_.max_render_scale;
  VkDevice dev = context_.device();
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = context_.queue_family();
  VK_CHECK(vkCreateCommandPool(dev, &pci, nullptr, &pool_));
  slots_.resize(settings_.frames_in_flight);
  for (Slot& s : slots_) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &s.cmd));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(dev, &fci, nullptr, &s.fence));
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = 2 * settings_.max_passes;
    VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &s.queries));
    s.pass_names.reserve(settings_.max_passes);
    s.host_ms.reserve(settings_.max_passes);
    s.cpu_ms.reserve(settings_.max_passes);
  }
  if (settings_.allow_profiling) {
    profile_cmds_.resize(settings_.max_passes);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = settings_.max_passes;
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, profile_cmds_.data()));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(dev, &fci, nullptr, &profile_fence_));
    MRGI_TRY(measure_submission_overhead());
  }
  decls_.reserve(settings_.max_passes);
  executes_.reserve(settings_.max_passes);
  shader_passes_.reserve(settings_.max_passes);
  if (const char* plant = std::getenv("MRGI_PLANT_SLOWDOWN")) {
    const std::string list = plant;
    for (size_t at = 0; at <= list.size();) {
      const size_t comma = std::min(list.find(',', at), list.size());
      const std::string spec = list.substr(at, comma - at);
      at = comma + 1;
      const size_t colon = spec.rfind(':');
      const double factor = colon == std::string::npos ? 0.0 : std::atof(spec.c_str() + colon + 1);
      if (colon == std::string::npos || colon == 0 || !(factor >= 1.0 && factor <= 100.0))
        return fail(ErrorKind::BadUsage, "MRGI_PLANT_SLOWDOWN='" + list + "': '" + spec +
                                             "' must be PASS:FACTOR with FACTOR in [1, 100] (several: comma-separated)");
      plants_.emplace_back(spec.substr(0, colon), factor);
    }
  }
  return ok_status();
}

FrameGraph::~FrameGraph() {
  VkDevice dev = context_.device();
  (void)wait_submitted();  // a frame that fails to finish here cannot be helped: release anyway
  if (profile_fence_) vkDestroyFence(dev, profile_fence_, nullptr);
  for (Slot& s : slots_) {
    if (s.fence) vkDestroyFence(dev, s.fence, nullptr);
    if (s.queries) vkDestroyQueryPool(dev, s.queries, nullptr);
  }
  if (pool_) vkDestroyCommandPool(dev, pool_, nullptr);
  for (ImageEntry& e : images_)
    if (e.owned) context_.destroy(e.gpu);
  for (BufferEntry& e : buffers_)
    if (e.owned)
      for (GpuBuffer& b : e.copies) context_.destroy(b);
}

static VkExtent2D relative_extent(uint32_t w, uint32_t h, float scale) {
  return {std::max(1u, uint32_t(std::ceil(double(w) * scale))), std::max(1u, uint32_t(std::ceil(double(h) * scale)))};
}

Expected<ImageHandle> FrameGraph::create_image(const ImageDesc& desc, VkImageUsageFlags usage) {
  const std::string what = "frame graph image '" + desc.name + "'";
  if (in_frame_) return fail(ErrorKind::BadUsage, what + ": resources are created at start-up, not inside a frame");
  if (desc.name.empty()) return fail(ErrorKind::BadUsage, "frame graph image: name must not be empty");
  for (const ImageEntry& e : images_)
    if (e.desc.name == desc.name) return fail(ErrorKind::BadUsage, what + ": name already used");
  if (desc.depth == 0) return fail(ErrorKind::BadUsage, what + ": depth must be >= 1");
  if (desc.depth > 1 && (desc.size_mode != SizeMode::Absolute || desc.layers != 1))
    return fail(ErrorKind::BadUsage, what + ": a 3D image (depth > 1) has an absolute size and one layer");
  VkExtent2D ext;
  if (desc.size_mode == SizeMode::Absolute) {
    if (desc.width == 0 || desc.height == 0)
      return fail(ErrorKind::BadUsage, what + ": absolute size needs width and height > 0");
    ext = {desc.width, desc.height};
  } else {
    if (!(desc.scale > 0.0f && desc.scale <= 4.0f))
      return fail(ErrorKind::BadUsage, what + ": scale " + std::to_string(desc.scale) + " must be in (0, 4]");
    const float s = desc.scale * (desc.follows_render_scale ? settings_.max_render_scale : 1.0f);
    ext = relative_extent(settings_.max_output_width, settings_.max_output_height, s);
  }
  ImageCreateDesc cd;
  cd.format = desc.format;
  cd.width = ext.width;
  cd.height = ext.height;
  cd.depth = desc.depth;
  cd.mip_levels = desc.mip_levels;
  cd.layers = desc.layers;
  cd.array_view = desc.array_view;
  cd.usage = usage | desc.extra_usage;
  cd.name = desc.name;
  auto img = context_.create_image(cd);
  if (!img) return img.error();
  ImageEntry e;
  e.desc = desc;
  e.gpu = *img;
  e.set_all_levels(ResourceState{});
  images_.push_back(std::move(e));
  return ImageHandle{uint32_t(images_.size() - 1)};
}

Expected<BufferHandle> FrameGraph::create_buffer(const BufferDesc& desc, VkBufferUsageFlags usage) {
  const std::string what = "frame graph buffer '" + desc.name + "'";
  if (in_frame_) return fail(ErrorKind::BadUsage, what + ": resources are created at start-up, not inside a frame");
  if (desc.name.empty()) return fail(ErrorKind::BadUsage, "frame graph buffer: name must not be empty");
  for (const BufferEntry& e : buffers_)
    if (e.desc.name == desc.name) return fail(ErrorKind::BadUsage, what + ": name already used");
  BufferEntry e;
  e.desc = desc;
  const bool texel = desc.texel_format != VK_FORMAT_UNDEFINED;
  if (texel) {
    // Texel sizes of the formats used so far; others are refused by name.
    const VkDeviceSize texel_bytes =
        desc.texel_format == VK_FORMAT_R32_UINT || desc.texel_format == VK_FORMAT_R32_SFLOAT ? 4
        : desc.texel_format == VK_FORMAT_R32G32B32A32_UINT                                   ? 16
                                                                                              : 0;
    if (texel_bytes == 0)
      return fail(ErrorKind::NotImplemented, what + ": texel_format " +
                                                 std::to_string(int(desc.texel_format)) +
                                                 " (only R32_UINT, R32_SFLOAT and R32G32B32A32_UINT views are implemented)");
    const VkDeviceSize texels = desc.size / texel_bytes;
    const uint32_t limit = context_.properties().limits.maxTexelBufferElements;
    if (desc.size % texel_bytes != 0 || texels > limit)
      return fail(ErrorKind::Device, what + ": " + std::to_string(desc.size) +
                                         " bytes as a texel buffer: a whole number of texels, at "
                                         "most " + std::to_string(limit) +
                                         " (this device's maxTexelBufferElements)");
    usage |= VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
  }
  const uint32_t copies = desc.per_frame_copies ? settings_.frames_in_flight : 1;
  for (uint32_t i = 0; i < copies; ++i) {
    auto b = context_.create_buffer(desc.size, usage | desc.extra_usage, desc.memory,
                                    copies > 1 ? desc.name + "#" + std::to_string(i) : desc.name);
    if (b && texel) {
      VkBufferViewCreateInfo vi{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
      vi.buffer = b->buffer;
      vi.format = desc.texel_format;
      vi.offset = 0;
      vi.range = desc.size;
      const VkResult r = vkCreateBufferView(context_.device(), &vi, nullptr, &b->texel_view);
      if (r != VK_SUCCESS) {
        context_.destroy(*b);
        b = fail(ErrorKind::Device, what + ": vkCreateBufferView failed (VkResult " +
                                        std::to_string(int(r)) + ")");
      }
    }
    if (!b) {
      for (GpuBuffer& made : e.copies) context_.destroy(made);
      return b.error();
    }
    e.copies.push_back(*b);
  }
  e.states.resize(copies);
  buffers_.push_back(std::move(e));
  return BufferHandle{uint32_t(buffers_.size() - 1)};
}

ImageHandle FrameGraph::import_image(const std::string& name, const GpuImage& image, VkImageLayout layout,
                                     bool history) {
  ImageEntry e;
  e.desc.name = name;
  e.desc.format = image.format;
  e.desc.size_mode = SizeMode::Absolute;
  e.desc.width = image.extent.width;
  e.desc.height = image.extent.height;
  e.desc.depth = image.depth;
  e.desc.mip_levels = image.mip_levels;
  e.desc.layers = image.layers;
  e.desc.history = history;
  e.gpu = image;
  e.owned = false;
  ResourceState st;
  st.layout = layout;
  e.set_all_levels(st);
  images_.push_back(std::move(e));
  return ImageHandle{uint32_t(images_.size() - 1)};
}

BufferHandle FrameGraph::import_buffer(const std::string& name, const GpuBuffer& buffer, bool history) {
  BufferEntry e;
  e.desc.name = name;
  e.desc.size = buffer.size;
  e.desc.memory = buffer.memory_usage;
  e.desc.history = history;
  e.copies.push_back(buffer);
  e.states.resize(1);
  e.owned = false;
  buffers_.push_back(std::move(e));
  return BufferHandle{uint32_t(buffers_.size() - 1)};
}

Expected<ImageHandle> FrameGraph::create_zero_image(const std::string& name, VkFormat format, VkImageUsageFlags usage,
                                                    uint32_t width, uint32_t height, uint32_t depth) {
  const uint32_t texel = bytes_per_texel(format);
  if (texel == 0)
    return fail(ErrorKind::BadUsage, "create_zero_image('" + name + "'): format " + std::to_string(int(format)) +
                                         " has no known texel size");
  ImageDesc d;
  d.name = name;
  d.format = format;
  d.size_mode = SizeMode::Absolute;
  d.width = width;
  d.height = height;
  d.depth = depth;
  auto image = create_image(d, usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  if (!image) return image.error();
  const std::vector<uint8_t> zero(size_t(width) * height * depth * texel, 0);
  MRGI_TRY(upload_image(*image, zero.data(), zero.size()));
  return *image;
}

Status FrameGraph::upload_image(ImageHandle image, const void* texels, VkDeviceSize size) {
  if (image.id >= images_.size()) return fail(ErrorKind::BadUsage, "upload_image: invalid image handle");
  if (in_frame_) return fail(ErrorKind::BadUsage, "upload_image('" + images_[image.id].desc.name +
                                                      "'): start-up only, not inside a frame");
  // Previous frames may still use it.
  MRGI_TRY(wait_submitted());
  ImageEntry& e = images_[image.id];
  // Leave it in the layout its usage allows, so the first pass's barrier is a valid transition.
  const VkImageLayout layout = (e.gpu.usage & VK_IMAGE_USAGE_SAMPLED_BIT) ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
                               : (e.gpu.usage & VK_IMAGE_USAGE_STORAGE_BIT) ? VK_IMAGE_LAYOUT_GENERAL
                                                                            : VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  MRGI_TRY(context_.upload_image(e.gpu, texels, size, layout));
  ResourceState st;
  st.layout = layout;
  e.set_all_levels(st);
  return ok_status();
}

// --- sizes ---------------------------------------------------------------------------------------

Status FrameGraph::set_output_size(uint32_t width, uint32_t height) {
  if (width == 0 || height == 0 || width > settings_.max_output_width || height > settings_.max_output_height)
    return fail(ErrorKind::BadUsage, "output size " + std::to_string(width) + "x" + std::to_string(height) +
                                         " must be non-zero and within the allocated " +
                                         std::to_string(settings_.max_output_width) + "x" +
                                         std::to_string(settings_.max_output_height));
  output_size_ = {width, height};
  return ok_status();
}

Status FrameGraph::set_render_scale(float scale) {
  if (!(scale > 0.0f && scale <= settings_.max_render_scale))
    return fail(ErrorKind::BadUsage, "render scale " + std::to_string(scale) + " must be in (0, " +
                                         std::to_string(settings_.max_render_scale) + "] (allocated maximum)");
  render_scale_ = scale;
  return ok_status();
}

VkExtent2D FrameGraph::extent(ImageHandle image) const {
  const ImageEntry& e = images_.at(image.id);
  if (e.desc.size_mode == SizeMode::Absolute) {
    const uint32_t d = e.divisor;
    return {(e.gpu.extent.width + d - 1) / d, (e.gpu.extent.height + d - 1) / d};
  }
  const float s = e.desc.scale * (e.desc.follows_render_scale ? render_scale_ : 1.0f);
  const VkExtent2D r = relative_extent(output_size_.width, output_size_.height, s);
  const uint32_t d = e.divisor;
  return {std::min((r.width + d - 1) / d, e.gpu.extent.width),
          std::min((r.height + d - 1) / d, e.gpu.extent.height)};
}

VkExtent3D FrameGraph::extent3d(ImageHandle image, uint32_t mip) const {
  const ImageEntry& e = images_.at(image.id);
  const VkExtent2D xy = extent(image);
  const uint32_t d = e.desc.size_mode == SizeMode::Absolute ? (e.gpu.depth + e.divisor - 1) / e.divisor : e.gpu.depth;
  return {std::max(1u, xy.width >> mip), std::max(1u, xy.height >> mip), std::max(1u, d >> mip)};
}

Status FrameGraph::set_extent_divisor(ImageHandle image, uint32_t divisor) {
  if (image.id >= images_.size())
    return fail(ErrorKind::BadUsage, "set_extent_divisor: invalid image handle");
  ImageEntry& e = images_[image.id];
  if (divisor < 1 || divisor > 64)
    return fail(ErrorKind::BadUsage, "set_extent_divisor: image '" + e.desc.name + "': divisor " +
                                         std::to_string(divisor) + " must be in 1..64");
  e.divisor = divisor;
  return ok_status();
}

VkExtent2D FrameGraph::allocated_extent(ImageHandle image) const { return images_.at(image.id).gpu.extent; }
const GpuImage& FrameGraph::gpu_image(ImageHandle image) const { return images_.at(image.id).gpu; }
const GpuBuffer& FrameGraph::gpu_buffer(BufferHandle buffer, uint32_t slot) const {
  const BufferEntry& e = buffers_.at(buffer.id);
  return e.copies.size() > 1 ? e.copies.at(slot) : e.copies[0];
}
const std::string& FrameGraph::name(ImageHandle image) const { return images_.at(image.id).desc.name; }
const std::string& FrameGraph::name(BufferHandle buffer) const { return buffers_.at(buffer.id).desc.name; }
VkFormat FrameGraph::texel_format(BufferHandle buffer) const {
  return buffers_.at(buffer.id).desc.texel_format;
}
void* FrameGraph::mapped(BufferHandle buffer, uint32_t slot) const { return gpu_buffer(buffer, slot).mapped; }

// --- frames --------------------------------------------------------------------------------------

Status FrameGraph::wait_submitted() const {
  VkDevice dev = context_.device();
  for (const Slot& s : slots_) {
    if (!s.submitted) continue;
    const VkResult w = vkWaitForFences(dev, 1, &s.fence, VK_TRUE, kFrameTimeoutNs);
    if (w == VK_TIMEOUT)
      return fail(ErrorKind::Timeout, "frame " + std::to_string(s.frame_index) + " did not finish on the GPU within " +
                                          std::to_string(kFrameTimeoutS) + " s (device hung or far too slow)");
    VK_CHECK(w);
  }
  return ok_status();
}

Expected<std::optional<FrameTimings>> FrameGraph::collect(uint32_t index) {
  Slot& s = slots_[index];
  if (!s.submitted) return std::optional<FrameTimings>{};
  VkDevice dev = context_.device();
  const VkResult w = vkWaitForFences(dev, 1, &s.fence, VK_TRUE, kFrameTimeoutNs);
  if (w == VK_TIMEOUT)
    return fail(ErrorKind::Timeout, "frame " + std::to_string(s.frame_index) + " did not finish on the GPU within " +
                                      std::to_string(kFrameTimeoutS) + " s (device hung or far too slow)");
  VK_CHECK(w);
  FrameTimings t;
  t.completed_s = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  VK_CHECK(vkResetFences(dev, 1, &s.fence));
  s.submitted = false;
  t.frame_index = s.frame_index;
  t.slot = index;
  t.culled = s.culled;
  const uint32_t n = uint32_t(s.pass_names.size());
  t.profiled = s.profiled;
  if (s.profiled) {
    for (uint32_t i = 0; i < n; ++i) {
      t.passes.push_back(PassTiming{s.pass_names[i], s.host_ms[i], s.cpu_ms[i]});
      t.total_ms += s.host_ms[i];
    }
  } else if (n > 0) {
    uint64_t ticks[2 * 1024];
    VK_CHECK(vkGetQueryPoolResults(dev, s.queries, 0, 2 * n, sizeof(uint64_t) * 2 * n, ticks, sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT));
    const uint32_t bits = context_.timestamp_valid_bits();
    const uint64_t mask = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
    const double ms_per_tick = context_.timestamp_period_ns() * 1e-6;
    for (uint32_t i = 0; i < n; ++i) {
      const uint64_t a = ticks[2 * i] & mask, b = ticks[2 * i + 1] & mask;
      t.passes.push_back(PassTiming{s.pass_names[i], double((b - a) & mask) * ms_per_tick});
    }
    t.total_ms = double(((ticks[2 * n - 1] & mask) - (ticks[0] & mask)) & mask) * ms_per_tick;
  }
  return std::optional<FrameTimings>(std::move(t));
}

Expected<std::optional<FrameTimings>> FrameGraph::begin_frame() {
  if (in_frame_) return fail(ErrorKind::BadUsage, "begin_frame: the previous frame was not submitted");
  // An app's semaphores belong to the frame they were given with: a frame that failed before
  // its submission leaves them unused, never to a later frame.
  submit_wait_count_ = 0;
  submit_signal_ = VK_NULL_HANDLE;
  const int64_t next = frame_index_ + 1;
  const uint32_t slot = uint32_t(next % int64_t(slots_.size()));
  auto done = collect(slot);
  if (!done) return done.error();
  VK_CHECK(vkResetCommandBuffer(slots_[slot].cmd, 0));
  frame_index_ = next;
  slot_ = slot;
  pass_count_ = 0;
  setup_error_.clear();
  outputs_.clear();
  compiled_valid_ = false;
  in_frame_ = true;
  return done;
}

void FrameGraph::add_pass(const std::string& name, PassKind kind, const SetupFn& setup, ExecuteFn execute) {
  // Reuse last frame's declarations in place so their strings and vectors keep their capacity.
  if (pass_count_ == decls_.size()) {
    decls_.emplace_back();
    executes_.emplace_back();
    shader_passes_.emplace_back();
  }
  shader_passes_[pass_count_].pipeline = nullptr;
  PassDecl& d = decls_[pass_count_];
  d.name.assign(name);
  d.kind = kind;
  d.uses.clear();
  d.side_effect = false;
  PassBuilder builder(*this, d);
  setup(builder);
  executes_[pass_count_] = std::move(execute);
  ++pass_count_;
  compiled_valid_ = false;
}

void FrameGraph::mark_output(ImageHandle image) { outputs_.push_back(ResourceRef{true, image.id}); }
void FrameGraph::mark_output(BufferHandle buffer) {
  outputs_.push_back(ResourceRef{false, uint32_t(images_.size()) + buffer.id});
}

void FrameGraph::update_resource_infos() {
  infos_.resize(images_.size() + buffers_.size());
  for (size_t i = 0; i < images_.size(); ++i) {
    ResourceInfo& r = infos_[i];
    const ImageEntry& e = images_[i];
    if (r.name != e.desc.name) r.name = e.desc.name;
    r.is_image = true;
    r.is_output = false;
    r.history = e.desc.history;
    r.host_read = false;
    r.mip_levels = e.gpu.mip_levels;
    r.initial = e.state;
    r.initial_mips = e.mip_states;
  }
  for (size_t i = 0; i < buffers_.size(); ++i) {
    ResourceInfo& r = infos_[images_.size() + i];
    const BufferEntry& e = buffers_[i];
    if (r.name != e.desc.name) r.name = e.desc.name;
    r.is_image = false;
    r.is_output = false;
    r.history = e.desc.history;
    r.host_read = e.desc.memory == MemoryUsage::Readback;
    r.initial = e.states.size() > 1 ? e.states[slot_] : e.states[0];
  }
  // A host-written buffer the GPU also writes and the host reads back (a camera frame converted
  // or copied on the GPU) is made visible to the host as a readback buffer is.
  for (const ResourceRef& o : outputs_)
    if (o.id < infos_.size()) {
      infos_[o.id].is_output = true;
      const MemoryUsage m = o.is_image ? MemoryUsage::DeviceLocal : buffers_[o.id - images_.size()].desc.memory;
      if (m == MemoryUsage::Upload || m == MemoryUsage::UploadHostRead) infos_[o.id].host_read = true;
    }
}

Status FrameGraph::compile() {
  if (!in_frame_) return fail(ErrorKind::BadUsage, "compile: call begin_frame first");
  if (!setup_error_.empty()) return fail(ErrorKind::BadUsage, setup_error_);
  for (const ResourceRef& o : outputs_)
    if (o.id >= images_.size() + buffers_.size())
      return fail(ErrorKind::BadUsage, "mark_output: invalid resource handle");
  update_resource_infos();
  const std::span<const PassDecl> decls(decls_.data(), pass_count_);
  for (const CacheEntry& e : cache_) {
    if (e.decls.size() == decls.size() && std::equal(decls.begin(), decls.end(), e.decls.begin()) &&
        e.infos == infos_) {
      compiled_ = e.compiled;  // element-wise copy into kept capacity
      compiled_valid_ = true;
      ++compile_cache_hits_;
      return ok_status();
    }
  }
  auto g = compile_graph(decls, infos_);
  if (!g) return g.error();
  if (g->passes.size() > settings_.max_passes)
    return fail(ErrorKind::BadUsage, std::to_string(g->passes.size()) + " passes run this frame, more than "
                                     "FrameGraphSettings.max_passes = " + std::to_string(settings_.max_passes));
  compiled_ = std::move(*g);
  compiled_valid_ = true;
  constexpr size_t kCacheEntries = 4;
  if (cache_.size() < kCacheEntries) cache_.emplace_back();
  CacheEntry& slot = cache_[cache_next_ % cache_.size()];
  cache_next_ = uint32_t((cache_next_ + 1) % kCacheEntries);
  slot.decls.assign(decls.begin(), decls.end());
  slot.infos = infos_;
  slot.compiled = compiled_;
  return ok_status();
}

void FrameGraph::record_barriers(VkCommandBuffer cmd, const std::vector<Barrier>& barriers) {
  if (barriers.empty()) return;
  std::vector<VkImageMemoryBarrier2>& image_barriers = image_barrier_scratch_;
  std::vector<VkBufferMemoryBarrier2>& buffer_barriers = buffer_barrier_scratch_;
  image_barriers.clear();
  buffer_barriers.clear();
  for (const Barrier& b : barriers) {
    if (b.resource.is_image) {
      const GpuImage& img = images_[b.resource.id].gpu;
      VkImageMemoryBarrier2 ib{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
      ib.srcStageMask = b.src_stages;
      ib.srcAccessMask = b.src_access;
      ib.dstStageMask = b.dst_stages;
      ib.dstAccessMask = b.dst_access;
      ib.oldLayout = b.old_layout;
      ib.newLayout = b.new_layout;
      ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      ib.image = img.image;
      ib.subresourceRange = {img.aspect, b.base_mip, b.mip_count, 0, img.layers};
      image_barriers.push_back(ib);
    } else {
      const uint32_t id = b.resource.id - uint32_t(images_.size());
      const GpuBuffer& buf = gpu_buffer(BufferHandle{id}, slot_);
      VkBufferMemoryBarrier2 bb{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
      bb.srcStageMask = b.src_stages;
      bb.srcAccessMask = b.src_access;
      bb.dstStageMask = b.dst_stages;
      bb.dstAccessMask = b.dst_access;
      bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      bb.buffer = buf.buffer;
      bb.offset = 0;
      bb.size = VK_WHOLE_SIZE;
      buffer_barriers.push_back(bb);
    }
  }
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.imageMemoryBarrierCount = uint32_t(image_barriers.size());
  di.pImageMemoryBarriers = image_barriers.data();
  di.bufferMemoryBarrierCount = uint32_t(buffer_barriers.size());
  di.pBufferMemoryBarriers = buffer_barriers.data();
  context_.fn().cmd_pipeline_barrier2(cmd, &di);
}

void FrameGraph::finish_execute(bool profiled) {
  // The GPU state at the end of this frame is where the next frame starts.
  for (size_t r = 0; r < compiled_.final_states.size(); ++r) {
    if (r < images_.size()) {
      images_[r].state = compiled_.final_states[r];
      if (images_[r].gpu.mip_levels > 1) images_[r].mip_states = compiled_.final_mip_states[r];
    } else {
      BufferEntry& e = buffers_[r - images_.size()];
      (e.states.size() > 1 ? e.states[slot_] : e.states[0]) = compiled_.final_states[r];
    }
  }
  Slot& slot = slots_[slot_];
  slot.pass_names.resize(compiled_.passes.size());
  for (size_t i = 0; i < compiled_.passes.size(); ++i) slot.pass_names[i].assign(compiled_.passes[i].name);
  slot.culled = compiled_.culled;
  slot.frame_index = frame_index_;
  slot.profiled = profiled;
}

Status FrameGraph::execute(VkCommandBuffer cmd) {
  if (!compiled_valid_) return fail(ErrorKind::BadUsage, "execute: compile() the frame first");
  const DeviceFunctions& fn = context_.fn();
  Slot& slot = slots_[slot_];
  const uint32_t n = uint32_t(compiled_.passes.size());
  if (n > 0) vkCmdResetQueryPool(cmd, slot.queries, 0, 2 * n);
  PassContext ctx(*this);
  for (uint32_t i = 0; i < n; ++i) {
    const CompiledPass& p = compiled_.passes[i];
    record_barriers(cmd, p.barriers);
    fn.cmd_write_timestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.queries, 2 * i);
    run_pass(cmd, p.pass_index, ctx);
    fn.cmd_write_timestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.queries, 2 * i + 1);
  }
  record_barriers(cmd, compiled_.final_barriers);
  finish_execute(false);
  return ok_status();
}

}  // namespace mrgi::gpu
