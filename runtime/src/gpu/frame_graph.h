// The frame graph: every GPU resource is declared and allocated once at start-up (sized for the
// largest quality level); each frame, passes are added with their declared reads and writes,
// compile() culls passes whose results nobody uses and derives every barrier and layout change
// from the declarations, and execute() records the passes with a timestamp pair each.
// Modelled on Filament's FrameGraph (reference-counted culling) and Granite's render graph.
//
// Frame loop (N = frames_in_flight slots, each with its own command buffer, fence, queries):
//   auto done = graph.begin_frame();   // waits only for the frame that used this slot N frames ago
//   graph.add_pass("shade", PassKind::Compute, [&](PassBuilder& b) { b.read(a, Access::Sampled);
//                  b.write(c, Access::StorageWrite); }, [&](VkCommandBuffer cmd, PassContext& p) {...});
//   graph.mark_output(readback);
//   graph.compile(); graph.submit();   // (or execute(cmd) into a command buffer of your own)
// `done` holds the per-pass GPU times of the frame that last used the slot; its Readback buffers
// (ring copies of that slot) may be read until submit().
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gpu/context.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "mrgi/runtime.h"

namespace mrgi::gpu {

// CPU time of every thread of this process so far, ms (the profiling mode's and the bench's CPU
// figures: on a CPU device the driver's worker threads do the GPU work).
double process_cpu_ms();

struct ImageHandle {
  uint32_t id = UINT32_MAX;
  bool valid() const { return id != UINT32_MAX; }
  bool operator==(const ImageHandle&) const = default;
};
struct BufferHandle {
  uint32_t id = UINT32_MAX;
  bool valid() const { return id != UINT32_MAX; }
  bool operator==(const BufferHandle&) const = default;
};

enum class SizeMode {
  Absolute,        // width x height texels
  OutputRelative,  // scale x the output size; the used extent follows set_output_size/render_scale
};

struct ImageDesc {
  std::string name;
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  SizeMode size_mode = SizeMode::OutputRelative;
  uint32_t width = 0, height = 0;  // Absolute only
  uint32_t depth = 1;              // > 1: a 3D image (Absolute only; layers must be 1)
  float scale = 1.0f;              // OutputRelative only: fraction of the output size (0, 4]
  // OutputRelative only: also scaled by the per-frame render scale (internal resolution knob).
  bool follows_render_scale = true;
  uint32_t mip_levels = 1;
  uint32_t layers = 1;
  // Its views (PassContext::view, ShaderPassBuilder::bind) are 2D arrays with one layer too, for
  // a shader's *2DArray* whose layer count varies with the scene (else 2D when layers is 1).
  bool array_view = false;
  // Persistent: contents survive across frames (temporal history). The last write of a frame is
  // always kept (never culled) and its first read in a frame sees the previous frame's contents.
  bool history = false;
  VkImageUsageFlags extra_usage = 0;  // usage beyond what the declared accesses imply
};

struct BufferDesc {
  std::string name;
  VkDeviceSize size = 0;  // bytes
  MemoryUsage memory = MemoryUsage::DeviceLocal;
  // One copy per frame slot (the handle resolves to the current slot's copy). Needed for Upload
  // buffers the host fills every frame and Readback buffers read frames later.
  bool per_frame_copies = false;
  bool history = false;   // as ImageDesc::history
  VkBufferUsageFlags extra_usage = 0;
  // Not VK_FORMAT_UNDEFINED: the buffer is also a storage texel buffer of this format, with a
  // view over all of it (PassContext::texel_view; GLSL imageBuffer / uimageBuffer). Lavapipe
  // reads such a view at per-lane indices with vector inserts, a storage buffer lane by lane in
  // a branchy loop (shaders/common/upload_gather.glsl has the figures).
  VkFormat texel_format = VK_FORMAT_UNDEFINED;
};

// How a pass touches a resource. Stages come from this and the pass kind.
enum class Access : uint8_t {
  Sampled,                  // texture fetch through a sampler (image)
  StorageRead,              // imageLoad / SSBO read
  StorageWrite,             // imageStore / SSBO write, previous contents not needed
  StorageReadWrite,         // read-modify-write (atomics, in-place filters)
  ColorAttachmentWrite,     // render target, cleared or overwritten
  ColorAttachmentReadWrite, // render target with blending or load
  DepthAttachmentWrite,     // depth test and write
  DepthAttachmentRead,      // depth test without write
  TransferSrc,
  TransferDst,
  VertexBuffer,
  IndexBuffer,
  UniformRead,
  IndirectRead,
  DepthAttachmentReadWrite, // depth test and write over loaded contents (e.g. real depth)
};
bool is_write(Access access);
bool is_read(Access access);
const char* to_string(Access access);

enum class PassKind : uint8_t { Compute, Graphics, Transfer };
const char* to_string(PassKind kind);

// --- The pure compile step (no Vulkan calls: tests inspect it without a GPU) ------------------

// `id` indexes the `resources` list given to compile_graph; `is_image` must match it.
struct ResourceRef {
  bool is_image = true;
  uint32_t id = 0;
  bool operator==(const ResourceRef&) const = default;
};

// A pass's use of a resource: of an image, the mip levels [base_mip, base_mip + mip_count)
// (mip_count 0: every level from base_mip), so a mip chain's pass may read level i - 1 and write
// level i of one image; a buffer has one level.
struct ResourceUse {
  ResourceRef resource;
  Access access = Access::Sampled;
  uint32_t base_mip = 0;
  uint32_t mip_count = 0;
  bool operator==(const ResourceUse&) const = default;
};

struct PassDecl {
  std::string name;
  PassKind kind = PassKind::Compute;
  std::vector<ResourceUse> uses;
  bool side_effect = false;  // never culled (e.g. writes something outside the graph)
  bool operator==(const PassDecl&) const = default;
};

// What the GPU last did to a resource, carried from frame to frame.
struct ResourceState {
  VkPipelineStageFlags2 write_stages = 0;  // stages of the last write not yet waited on
  VkAccessFlags2 write_access = 0;
  VkPipelineStageFlags2 read_stages = 0;   // reads since that write (a write must wait on them)
  VkAccessFlags2 visible_access = 0;       // accesses the last write was already made visible to
  VkPipelineStageFlags2 visible_stages = 0;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  bool operator==(const ResourceState&) const = default;
};

struct ResourceInfo {
  std::string name;
  bool is_image = true;
  bool is_output = false;     // marked output or history: its final writer is kept
  bool history = false;       // contents must be preserved across frames (no discard on write)
  bool host_read = false;     // a Readback buffer: the frame ends with a barrier to HOST_READ
  uint32_t mip_levels = 1;    // images: state is tracked per level; buffers: 1
  ResourceState initial;      // state at the start of the frame (of every level, unless...)
  std::vector<ResourceState> initial_mips;  // ...this has one per level (levels that differ)
  bool operator==(const ResourceInfo&) const = default;
};

struct Barrier {
  ResourceRef resource;
  std::string resource_name;
  uint32_t base_mip = 0;   // images: the levels it covers (resolved, never 0 levels)
  uint32_t mip_count = 1;
  VkPipelineStageFlags2 src_stages = 0;
  VkAccessFlags2 src_access = 0;
  VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;  // images only
  VkPipelineStageFlags2 dst_stages = 0;
  VkAccessFlags2 dst_access = 0;
  VkImageLayout new_layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

struct CompiledPass {
  uint32_t pass_index = 0;          // index into the declared pass list
  std::string name;
  std::vector<Barrier> barriers;    // recorded before the pass
};

struct CompiledGraph {
  std::vector<CompiledPass> passes;       // the passes that run, in declaration order
  std::vector<std::string> culled;        // names of the passes culled
  std::vector<Barrier> final_barriers;    // after the last pass (host reads of readback buffers)
  std::vector<ResourceState> final_states;  // per resource, the state at the end of the frame (level 0)
  // Per resource with more than one level: every level's state (empty for the others).
  std::vector<std::vector<ResourceState>> final_mip_states;
  // Barriers naming this resource (by name), in order; for tests.
  std::vector<Barrier> barriers_for(const std::string& resource_name) const;
  bool runs(const std::string& pass_name) const;
};

// Culls and derives barriers, per mip level of an image. Errors (BadUsage) name the pass and
// resource: a resource used twice by one pass (for an image: on overlapping levels), levels
// beyond the image's, an image access on a buffer or the reverse, an unknown resource id.
Expected<CompiledGraph> compile_graph(std::span<const PassDecl> passes,
                                      std::span<const ResourceInfo> resources);

// Stage/access/layout one use implies (what the barrier derivation uses).
struct AccessInfo {
  VkPipelineStageFlags2 stages = 0;
  VkAccessFlags2 access = 0;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};
AccessInfo access_info(PassKind kind, Access access, bool is_image, bool depth_format);

// --- The runtime graph --------------------------------------------------------------------------

class FrameGraph;

class PassBuilder {
 public:
  PassBuilder(const PassBuilder&) = default;
  void read(ImageHandle image, Access access = Access::Sampled);
  void write(ImageHandle image, Access access = Access::StorageWrite);
  void read(BufferHandle buffer, Access access = Access::StorageRead);
  void write(BufferHandle buffer, Access access = Access::StorageWrite);
  // Mip levels [base_mip, base_mip + mip_count) of an image only (PassContext::view(h, mip)
  // gives one level's view): a mip chain's pass reads level i - 1 and writes level i.
  void read(ImageHandle image, Access access, uint32_t base_mip, uint32_t mip_count = 1);
  void write(ImageHandle image, Access access, uint32_t base_mip, uint32_t mip_count = 1);
  void side_effect();  // keep this pass even if nothing reads what it writes

 private:
  friend class FrameGraph;
  friend class ShaderPassBuilder;
  PassBuilder(FrameGraph& graph, PassDecl& decl) : graph_(graph), decl_(decl) {}
  FrameGraph& graph_;
  PassDecl& decl_;
};

// A pass bound to one pipeline: its resources are bound by the names its shaders declare
// (gpu/reflect.h) and each bind() is also the pass's declared use, its access read from the
// declaration (a storage image or buffer: readonly -> StorageRead, writeonly -> StorageWrite,
// neither -> StorageReadWrite; a sampler2D/3D -> Sampled; a uniform block -> UniformRead). The graph
// binds the pipeline and pushes the descriptors before the pass's execute callback, which pushes
// constants and dispatches or draws. A name the shader does not declare, a kind that does not fit
// (an image for a buffer), or a shader binding left unbound fails compile() naming the pass, the
// pipeline and the binding.
class ShaderPassBuilder {
 public:
  void bind(std::string_view name, ImageHandle image);                   // every level
  void bind(std::string_view name, ImageHandle image, uint32_t mip);     // one level's view
  void bind_sampled(std::string_view name, ImageHandle image, VkSampler sampler);  // sampler2D, sampler3D
  void bind(std::string_view name, BufferHandle buffer);
  // A storage image or buffer the pass writes in part (tiles) over what an earlier pass of the
  // frame wrote there: declared StorageReadWrite whatever the shader's qualifier, so that earlier
  // write is neither culled as unread nor discarded by a layout transition.
  void bind_over(std::string_view name, ImageHandle image);
  void bind_over(std::string_view name, BufferHandle buffer);
  // Uses that are not descriptors (attachments, vertex / index / indirect buffers).
  PassBuilder& uses() { return base_; }

 private:
  friend class FrameGraph;
  ShaderPassBuilder(FrameGraph& graph, PassBuilder base, const Pipeline& pipeline, uint32_t pass)
      : graph_(graph), base_(base), pipeline_(pipeline), pass_(pass) {}
  void bind_resource(std::string_view name, ResourceRef ref, uint32_t mip, bool one_level, VkSampler sampler,
                     bool over = false);
  FrameGraph& graph_;
  PassBuilder base_;
  const Pipeline& pipeline_;
  uint32_t pass_;
};

// Given to a pass's execute callback.
class PassContext {
 public:
  VkImage image(ImageHandle h) const;
  VkImageView view(ImageHandle h) const;              // every level
  VkImageView view(ImageHandle h, uint32_t mip) const;  // one level
  VkFormat format(ImageHandle h) const;
  VkExtent2D extent(ImageHandle h) const;   // the used extent this frame (<= allocated)
  VkExtent3D extent3d(ImageHandle h, uint32_t mip = 0) const;  // with depth, of one level
  VkBuffer buffer(BufferHandle h) const;    // the current slot's copy
  VkBufferView texel_view(BufferHandle h) const;  // its BufferDesc::texel_format view
  VkDeviceSize buffer_size(BufferHandle h) const;
  void* mapped(BufferHandle h) const;       // current slot's mapping (Upload/Readback)
  VkExtent2D output_size() const;
  float render_scale() const;
  int64_t frame_index() const;
  uint32_t slot() const;
  const Context& context() const;

 private:
  friend class FrameGraph;
  explicit PassContext(const FrameGraph& g) : graph_(g) {}
  const FrameGraph& graph_;
};

struct FrameGraphSettings {
  uint32_t max_output_width = 640;   // pixels: OutputRelative images are allocated for this
  uint32_t max_output_height = 480;
  float max_render_scale = 1.0f;     // (0, 1]; OutputRelative images also x this at most
  uint32_t frames_in_flight = 2;     // 1..3
  uint32_t max_passes = 128;         // timestamp queries per slot = 2 x this (dir paper: 78 passes)
  // Profiling mode (set_profiling): each pass is submitted on its own and waited for, and its
  // time is the host's wall clock from submit to fence. Needed where the driver's timestamps do
  // not bracket the work they surround: lavapipe writes a timestamp when a rasteriser thread
  // reaches it in its bins, while compute dispatches and vertex work run on the queue thread,
  // so a compute pass after a draw reads as the draw's tail and a draw's fragments land in the
  // next pass (see FrameTimings::profiled). Costs the overlap of passes and one submit and
  // wake-up per pass (about 0.05 ms each on lavapipe).
  bool allow_profiling = true;       // allocates max_passes command buffers for it at start-up
};

// Per-pass GPU times of one completed frame.
struct FrameTimings {
  int64_t frame_index = -1;
  uint32_t slot = 0;
  std::vector<PassTiming> passes;    // passes that ran, in order, milliseconds
  double total_ms = 0.0;             // first pass start to last pass end (profiled: the sum)
  std::vector<std::string> culled;
  // True when the frame ran in profiling mode: pass times are host-timed submissions and add up
  // to total_ms. False: GPU timestamps (on lavapipe they misattribute; see FrameGraphSettings).
  bool profiled = false;
  // Host steady-clock seconds when the host saw the frame complete (its fence wait returned).
  double completed_s = 0.0;
};

class FrameGraph {
 public:
  static Expected<std::unique_ptr<FrameGraph>> create(Context& context,
                                                      const FrameGraphSettings& settings);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Start-up: resources are allocated here, at once. Usage flags are given by `usage` (what the
  // passes will declare); errors name the resource and the rule.
  Expected<ImageHandle> create_image(const ImageDesc& desc, VkImageUsageFlags usage);
  Expected<BufferHandle> create_buffer(const BufferDesc& desc, VkBufferUsageFlags usage);
  // External resources (owned by the caller, which keeps them alive). `layout` is their current
  // layout; the graph tracks it from then on.
  ImageHandle import_image(const std::string& name, const GpuImage& image,
                           VkImageLayout layout, bool history = true);
  BufferHandle import_buffer(const std::string& name, const GpuBuffer& buffer,
                             bool history = true);
  // Fills an image with texels at start-up (staging copy, waits), leaving it SHADER_READ_ONLY
  // (sampled usage), GENERAL (storage) or TRANSFER_DST; the graph tracks the layout.
  Status upload_image(ImageHandle image, const void* texels, VkDeviceSize size);
  // A stand-in bound where a pass's shader declares an image the frame does not have (its path
  // compiled or branched out): `width` x `height` x `depth` texels of `format`, Absolute, filled
  // with zeros at start-up (defined contents, never read).
  Expected<ImageHandle> create_zero_image(const std::string& name, VkFormat format, VkImageUsageFlags usage,
                                          uint32_t width = 1, uint32_t height = 1, uint32_t depth = 1);

  // Per-frame size knobs: the used extent of OutputRelative images. Never reallocates; values
  // beyond what was allocated for are BadUsage.
  Status set_output_size(uint32_t width, uint32_t height);
  Status set_render_scale(float scale);
  // Per image: its used extent becomes ceil(relative extent / divisor) (1 = the relative extent),
  // for a technique stage that runs at a fraction of the internal resolution on some levels
  // (ssrt's geometry at its transfer's cell size). Absolute images (3D too): every dimension of
  // the allocated size / divisor (a volume's cheaper levels). Never reallocates.
  Status set_extent_divisor(ImageHandle image, uint32_t divisor);
  VkExtent2D output_size() const { return output_size_; }
  float render_scale() const { return render_scale_; }
  VkExtent2D extent(ImageHandle image) const;  // used extent now
  VkExtent3D extent3d(ImageHandle image, uint32_t mip = 0) const;  // used extent of one level
  VkExtent2D allocated_extent(ImageHandle image) const;
  const GpuImage& gpu_image(ImageHandle image) const;
  const GpuBuffer& gpu_buffer(BufferHandle buffer, uint32_t slot) const;
  const std::string& name(ImageHandle image) const;
  const std::string& name(BufferHandle buffer) const;
  VkFormat texel_format(BufferHandle buffer) const;  // BufferDesc::texel_format

  // Frame loop.
  // Waits for the slot's previous frame (if any), reads its timestamps, resets the slot, clears
  // the pass list. Returns that previous frame's timings, or nullopt when the slot was unused.
  Expected<std::optional<FrameTimings>> begin_frame();
  using SetupFn = std::function<void(PassBuilder&)>;
  using ExecuteFn = std::function<void(VkCommandBuffer, PassContext&)>;
  void add_pass(const std::string& name, PassKind kind, const SetupFn& setup, ExecuteFn execute);
  // A pass of one pipeline whose descriptors the graph binds (ShaderPassBuilder). `pipeline`
  // must outlive the frame.
  using ShaderSetupFn = std::function<void(ShaderPassBuilder&)>;
  void add_shader_pass(const std::string& name, PassKind kind, const Pipeline& pipeline,
                       const ShaderSetupFn& setup, ExecuteFn execute);
  void mark_output(ImageHandle image);
  void mark_output(BufferHandle buffer);
  Status compile();
  const CompiledGraph& compiled() const { return compiled_; }
  // Records barriers, passes and timestamps into `cmd` (begun by the caller).
  Status execute(VkCommandBuffer cmd);
  // Begins the slot's command buffer, execute()s, ends and submits it with the slot's fence.
  Status submit();
  // Semaphores for this frame's submission (binary; null is ignored): each `wait` before the
  // commands of `stage` run (at most kMaxSubmitWaits a frame: the app's input images' and its
  // output image's), `signal` when the frame's commands are done. Cleared by submit() and by
  // begin_frame() (a frame that failed before its submission does not pass them on).
  static constexpr uint32_t kMaxSubmitWaits = 2;
  Status add_submit_wait(VkSemaphore wait, VkPipelineStageFlags2 stage);
  void set_submit_signal(VkSemaphore signal) { submit_signal_ = signal; }
  // Waits for every frame in flight; returns their timings oldest first.
  Expected<std::vector<FrameTimings>> flush();
  // Waits until every frame submitted and not yet collected has completed (their slots' fences;
  // never the whole queue, which may be the app's: mrgi/vulkan_device.h). Timeout naming the
  // frame where one does not finish.
  Status wait_submitted() const;
  // Profiling mode from the next submit() on (FrameGraphSettings::allow_profiling must be set):
  // each pass its own submission, host-timed. BadUsage when the graph was made without it.
  Status set_profiling(bool on);
  bool profiling() const { return profiling_; }
  // What one empty submission costs from submit to fence here (the fastest of a few, measured at
  // start-up when profiling is allowed): subtracted from every profiled pass, so a pass's time
  // is its work and a frame of many short passes does not read longer than it runs.
  double submission_overhead_ms() const { return submission_overhead_ms_; }

  int64_t frame_index() const { return frame_index_; }   // of the frame being built
  uint32_t slot() const { return slot_; }
  uint32_t frames_in_flight() const { return settings_.frames_in_flight; }
  // Host pointer of a Readback/Upload buffer's copy in `slot` (e.g. FrameTimings::slot).
  void* mapped(BufferHandle buffer, uint32_t slot) const;
  Context& context() const { return context_; }
  // Frames whose compile() reused a cached result (same passes, same resource states): in steady
  // state the graph is compiled once and then only looked up.
  uint64_t compile_cache_hits() const { return compile_cache_hits_; }

 private:
  friend class PassContext;
  friend class PassBuilder;
  friend class ShaderPassBuilder;
  // A shader pass's descriptor, resolved when the pass is recorded.
  struct BoundDescriptor {
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    ResourceRef resource;
    uint32_t mip = 0;
    bool one_level = false;
    VkSampler sampler = VK_NULL_HANDLE;
  };
  struct ShaderPassData {
    const Pipeline* pipeline = nullptr;  // null: a plain pass
    std::vector<BoundDescriptor> descriptors;
  };
  std::vector<ShaderPassData> shader_passes_;  // parallel to decls_
  std::string setup_error_;                     // the first bind() error this frame
  void bind_and_push(VkCommandBuffer cmd, const ShaderPassData& data) const;
  void run_pass(VkCommandBuffer cmd, uint32_t pass_index, PassContext& ctx);
  struct ImageEntry;
  struct BufferEntry;
  struct Slot;
  struct PassEntry;
  FrameGraph(Context& context, const FrameGraphSettings& settings);
  Status init();
  Expected<std::optional<FrameTimings>> collect(uint32_t slot_index);
  void update_resource_infos();
  struct CacheEntry {
    std::vector<PassDecl> decls;
    std::vector<ResourceInfo> infos;
    CompiledGraph compiled;
  };

  Context& context_;
  FrameGraphSettings settings_;
  std::vector<ImageEntry> images_;
  std::vector<BufferEntry> buffers_;
  std::vector<Slot> slots_;
  std::array<VkSemaphoreSubmitInfo, kMaxSubmitWaits> submit_waits_{};
  uint32_t submit_wait_count_ = 0;
  VkSemaphore submit_signal_ = VK_NULL_HANDLE;
  // `si` with this frame's semaphores (add_submit_wait, set_submit_signal), which are then cleared.
  void add_submit_semaphores(VkSubmitInfo2& si, VkSemaphoreSubmitInfo& signal);
  std::vector<PassDecl> decls_;     // first pass_count_ are this frame's; the rest keep capacity
  std::vector<ExecuteFn> executes_;
  uint32_t pass_count_ = 0;
  std::vector<ResourceInfo> infos_;
  std::vector<CacheEntry> cache_;   // the last few distinct compiled frames (ping-pong graphs)
  uint32_t cache_next_ = 0;
  uint64_t compile_cache_hits_ = 0;
  std::vector<ResourceRef> outputs_;
  CompiledGraph compiled_;
  bool compiled_valid_ = false;
  // Reused every frame (capacity kept) so recording allocates nothing once warm.
  std::vector<VkImageMemoryBarrier2> image_barrier_scratch_;
  std::vector<VkBufferMemoryBarrier2> buffer_barrier_scratch_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  // Profiling mode: one command buffer per pass and a fence, allocated at start-up.
  std::vector<VkCommandBuffer> profile_cmds_;
  VkFence profile_fence_ = VK_NULL_HANDLE;
  bool profiling_ = false;
  double submission_overhead_ms_ = 0.0;
  // Test hook for the regression checks (perf/README.md): MRGI_PLANT_SLOWDOWN=PASS:FACTOR[,...]
  // makes each pass PASS take FACTOR times as long in profiling mode (the host spins the extra
  // time after its fence). Read once at creation; empty = off.
  std::vector<std::pair<std::string, double>> plants_;
  Status submit_profiled();
  Status measure_submission_overhead();
  // Submits `cmd` alone with the profiling fence and waits: host ms from submit to fence.
  // `pass` names the pass for errors and the test hook (nullptr: the empty calibration submit).
  Expected<double> submit_and_wait(VkCommandBuffer cmd, const std::string* pass);
  void record_barriers(VkCommandBuffer cmd, const std::vector<Barrier>& barriers);
  void finish_execute(bool profiled);
  VkExtent2D output_size_{0, 0};
  float render_scale_ = 1.0f;
  int64_t frame_index_ = -1;
  uint32_t slot_ = 0;
  bool in_frame_ = false;
};

}  // namespace mrgi::gpu
