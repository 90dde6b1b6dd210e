/// \file
/// The public API: create a Runtime for a capture's cameras and scene, feed it frames, get
/// composited RGBA8 frames and per-frame statistics back. In the order an app needs it:
///  1. create_runtime() with a CameraSetup, a SceneDesc (mrgi/scene.h) and RuntimeSettings;
///  2. Runtime::process() per camera frame (mrgi/frame.h), flush() at the end of a stream;
///  3. what comes back: FrameOutput (image, mask, FrameStats, the light);
///  4. the settings: RuntimeSettings, DeviceSettings, SchedulerSettings;
///  5. devices: list_devices();
///  6. techniques and their quality levels: choose_technique(), technique_ladder().
/// Research-only ablations live in mrgi/research.h; an app does not need them.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/frame.h"
#include "mrgi/light_estimate.h"
#include "mrgi/scene.h"

namespace mrgi {

class Runtime;
struct RuntimeSettings;
struct DeviceInfo;
struct FrameOutput;
struct ResearchSettings;  // mrgi/research.h
struct AppVulkanDevice;   // mrgi/vulkan_device.h
struct AppOutputImage;    // mrgi/vulkan_device.h
struct AppInputImages;    // mrgi/vulkan_device.h

// ---------------------------------------------------------------------------------------------
// 1-2. Creating a runtime and running frames
// ---------------------------------------------------------------------------------------------

/// The capture's cameras (capture.json): colour and depth intrinsics in pixels, the depth image's
/// units and the exposure.
struct CameraSetup {
  Intrinsics color;
  Intrinsics depth;
  double depth_scale = 5000.0;  ///< depth image units per metre (TUM: 5000)
  double exposure = 1.0;        ///< linear radiance -> linear camera value, before the sRGB curve
  /// The environment camera's model (capture.json `env_camera`), for frames that carry env
  /// images (InputFrame::env); without it those images cannot be mapped to directions.
  std::optional<EnvCamera> env_camera;
};

/// Creates a runtime for `cameras` and `scene`: picks the Vulkan device, loads the scene's glTF
/// models and environment, builds the technique's frame graph and allocates everything for its
/// most expensive level (nothing is allocated per frame after this). Takes seconds on a CPU
/// device (pipeline compilation). The app owns the returned runtime; it keeps no reference to
/// the arguments. Errors: BadUsage naming the setting for settings out of range or a knob the
/// technique refuses; BadInput naming the file and field for a scene, model or environment that
/// breaks its rules; NotFound for an unknown technique or no device matching the selector;
/// Device where Vulkan fails.
MRGI_API Expected<std::unique_ptr<Runtime>> create_runtime(const RuntimeSettings& settings,
                                                  const CameraSetup& cameras,
                                                  const SceneDesc& scene);

/// Thread safety: a Runtime is not thread-safe. Call its methods from one thread at a time
/// (synchronise externally if several threads drive it); process() does its recording and host
/// work on the calling thread, and the Vulkan driver runs the frames on its own threads. Each
/// Runtime owns its own Vulkan instance, device and frame graph; what runtimes share is
/// process-wide: DeviceSettings::keep_freed_memory's malloc setting.
class MRGI_API Runtime {
 public:
  virtual ~Runtime() = default;
  /// Processes one frame. Frames are pipelined: the call given frame k returns frame
  /// k - frames_in_flight (with 2 in flight, frame 0 comes back from the call given frame 2; the
  /// first frames_in_flight calls return nothing); flush() returns the last frames_in_flight frames
  /// in order at the end of a stream (tests/technique/frame_order_test.cpp). Once per
  /// runtime, a technique that estimates from the frames themselves (ssrt's light) has its first
  /// frame run twice, waiting for the first run, so that frame is lit by its own estimate; with
  /// the level on kAutoLevel the first frame is also run once in every frame slot first (the
  /// driver's first use of pipelines and slot memory would otherwise be charged to the budget).
  /// That call returns the frames still in flight at once, and the frame's stats note the runs.
  virtual Expected<std::vector<FrameOutput>> process(const InputFrame& frame) = 0;
  /// process(), with the frame's composite written into the app's image on the app's device
  /// (mrgi/vulkan_device.h AppOutputImage) instead of read back: zero host copies of the
  /// output. The outputs returned are earlier frames', as process()'s; one whose frame went to
  /// an app image has no image or mask. BadUsage on a runtime not made on the app's device
  /// (DeviceSettings::app_device), for a null image, a format other than R8G8B8A8 UNORM / SRGB
  /// or a final layout an image cannot be left in.
  virtual Expected<std::vector<FrameOutput>> process(const InputFrame& frame, const AppOutputImage& target) = 0;
  /// process(), with the frame's colour and depth given as the app's images on the app's device
  /// (mrgi/vulkan_device.h AppInputImages) instead of host memory: the GPU copies them at the
  /// start of the frame's submission, the host copies nothing. `frame` carries the rest (index,
  /// timestamps, pose, environment image) with color, color_yuv and depth empty. With `target`
  /// the composite goes to the app's image too (zero host copies of frame images,
  /// FrameStats::host_copy_bytes 0); without it, it is read back as process()'s. The host's
  /// readers of the camera (the light stage's estimates, the techniques' reuse tests) take an
  /// earlier frame (RuntimeSettings::lagged_camera_reads). BadUsage on a runtime not made on the
  /// app's device, for a null image, a format or layout it does not take, one semaphore as both
  /// the input's and the output's wait, or a frame that also carries images in host memory.
  virtual Expected<std::vector<FrameOutput>> process(const InputFrame& frame, const AppInputImages& images,
                                                     const AppOutputImage* target = nullptr) = 0;
  virtual Expected<std::vector<FrameOutput>> flush() = 0;
  /// Hands a delivered frame back once the caller is done with it: a later process() or flush()
  /// fills its image and mask instead of allocating new ones. Optional, but a live loop should:
  /// each new output image is fresh memory the OS zeroes page by page (at 640x480, 1.5 MB a
  /// frame: 75 % of the host thread's time in a sustained ssrt run on lavapipe, on cores the
  /// renderer needs). Frames of another size are dropped; at most frames_in_flight + 1 are kept.
  virtual void recycle(FrameOutput&& done) = 0;
  virtual const DeviceInfo& device() const = 0;
  virtual const std::string& technique() const = 0;  ///< the technique running (auto: the chosen one)
  virtual double memory_mib() const = 0;      ///< everything allocated at start-up, MiB
  virtual int level_count() const = 0;
  virtual std::vector<std::string> level_names() const = 0;
  /// Fixes the level from the next frame on (kAutoLevel: the scheduler chooses again). Never
  /// allocates. BadUsage outside kAutoLevel, 0..level_count()-1.
  virtual Status set_level(int level) = 0;
  /// The frame budget from the next frame on (ms, > 0); BadUsage otherwise.
  virtual Status set_frame_budget_ms(double budget_ms) = 0;
  /// Profiling mode from the next frame on (RuntimeSettings::profile_passes); never allocates.
  virtual Status set_profiling(bool on) = 0;
  /// The virtual objects by slot: scene.json's (SceneDesc::virtual_objects) in its order, then
  /// RuntimeSettings::objects.objects slots for objects added at run time; the slots are fixed
  /// at start-up (object_count()), a slot holds an object or is empty (has_object).
  /// set_object_placement moves one from the next process() on (an app's object moving),
  /// replacing its scene.json motion from then on; it never allocates. BadUsage for an index out
  /// of range or an empty slot, a non-finite placement or a scale that is not positive.
  virtual size_t object_count() const = 0;
  virtual bool has_object(size_t object) const = 0;
  virtual Status set_object_placement(size_t object, const Placement& placement) = 0;
  /// Shows (true) or hides (false) object i from the next process() on, keeping its room: a
  /// hidden object is not drawn, lit, shadowed or reflected; with none shown, frames are the
  /// camera frame. BadUsage for an index out of range or an empty slot.
  virtual Status set_object_visible(size_t object, bool visible) = 0;
  /// Loads a glTF (.gltf / .glb) and places it in the first empty slot, shown from the next
  /// process() on, within the room stated at creation (RuntimeSettings::objects: slots, meshes,
  /// triangles, vertices, textures); returns the slot. Its data for every technique (vertices,
  /// levels of detail, materials, textures, sphere proxies, the ISMs' triangle list, voxelisation)
  /// is ready for that frame; no memory is allocated. Host work on the calling thread (loading,
  /// simplification: tens of ms for a 10k-triangle model) and a transfer for each of its
  /// textures, ordered after the frames in flight and waited for on its own fence. Errors: NotFound or BadInput naming the file for a
  /// glTF that is missing or cannot be read; BadUsage naming the capacity that is full (no slot, meshes, triangles,
  /// vertices, texture layers), a material the runtime was not prepared for (glossy, emissive:
  /// ObjectCapacity) or a mirror or glass material; the runtime is unchanged after any error.
  virtual Expected<size_t> add_object(const std::string& gltf_path, const Placement& placement) = 0;
  /// Takes object i out from the next process() on and frees its room (an added object's or
  /// scene.json's) for later add_object calls; frames still on the device keep what they were
  /// recorded with. BadUsage for an index out of range or an empty slot.
  virtual Status remove_object(size_t object) = 0;
  /// The lamps: scene.json's (SceneDesc::lights), in its order, capacity fixed at start-up.
  /// set_lamp changes lamp i from the next process() on: moved, turned, recoloured, dimmed to 0
  /// (off: an app that adds lamps later declares them dark at start-up) or back; its kind (type,
  /// real) stays. Never allocates. BadUsage naming the field for an index out of range or a lamp
  /// scene.json would refuse.
  virtual size_t lamp_count() const = 0;
  virtual Status set_lamp(size_t lamp, const LightDesc& desc) = 0;
};

// ---------------------------------------------------------------------------------------------
// 3. What a frame gives back
// ---------------------------------------------------------------------------------------------

struct PassTiming {
  std::string name;
  double gpu_ms = 0.0;
  /// Profiled frames: the process's CPU time (every thread: on a CPU device the driver's workers
  /// run the pass) over the pass's submission, ms; 0 otherwise. Over gpu_ms x the device's
  /// threads it says how well a pass keeps them busy, and it moves less with other tenants' load.
  double cpu_ms = 0.0;
};

struct FrameStats {
  int64_t frame_index = 0;
  /// Time per pass that ran, ms: host-timed submissions when `profiled`, else GPU timestamps
  /// (on lavapipe those do not bracket the work: see RuntimeSettings::profile_passes).
  std::vector<PassTiming> passes;
  double gpu_total_ms = 0.0;           ///< first to last timestamp; profiled: the sum of the passes
  bool profiled = false;               ///< the frame ran in profiling mode
  /// Host time of process() for this frame: checks, upload, recording and submission. Not the
  /// frame time: the GPU runs the frame after process() returns (frames are pipelined).
  double record_ms = 0.0;
  /// Host std::chrono::steady_clock seconds when the runtime saw the frame complete: the
  /// difference between two frames' values is the sustained frame interval a live device sees.
  double completed_s = 0.0;
  /// Host time spent on this frame outside the GPU work: process() (record_ms, less the passes'
  /// own time in profiling mode, where process() waits for each) plus reading the output back.
  /// On a CPU device this competes with the passes for the same cores, so a frame's sustained
  /// wall clock is about its passes plus this.
  double host_ms = 0.0;
  /// Bytes of frame images the host wrote between the app and the runtime for this frame: the
  /// input's colour (4 bytes a pixel in the upload) and depth into the upload buffers (none for
  /// a frame given as the app's images, AppInputImages) and, unless the composite went to an app
  /// image (AppOutputImage), the output's image and mask back. A host-memory frame into an app
  /// image on a CPU device at the camera's size also counts the camera frame the host expands
  /// under the composite's tiles (cheaper there than a pass over every pixel; from app images a
  /// GPU pass writes it).
  uint64_t host_copy_bytes = 0;
  /// CPU time of the light stage this frame (light/light_stage.h: environment sampling or the
  /// probeless system's part and solve) on the calling thread, ms; inside record_ms and host_ms.
  double light_ms = 0.0;
  int level = 0;
  /// The internal resolution this frame ran at, as a fraction of the output's side (the level's
  /// internal scale x the scheduler's factor).
  float internal_scale = 1.0f;
  /// What the frame cost, ms: device time (first to last timestamp; profiled: the passes' sum)
  /// plus host_ms on a CPU device, the larger of the two on a GPU. What the scheduler reads.
  double cost_ms = 0.0;
  double predicted_ms = 0.0;  ///< the scheduler's prediction of cost_ms when it chose this frame's quality
  double budget_ms = 0.0;     ///< RuntimeSettings::frame_budget_ms when the frame was recorded
  bool scheduled = false;     ///< the level and scale were the scheduler's (kAutoLevel)
  std::vector<std::string> skipped;    ///< passes culled or skipped this frame, with reason
  /// Conditions worth knowing about this frame, e.g. "pose: none given, previous pose used".
  std::vector<std::string> notes;
};

struct FrameOutput {
  ImageRGBA8 image;    ///< composited frame, output size
  FrameStats stats;
  /// Output size; 255 where a virtual object is seen (composited as TM(L_rv)), 0 on real pixels.
  /// For RDE over real / virtual pixels (metrics.h).
  Image<uint8_t, 1> virtual_mask;
  /// The light the runtime lights with, as SH radiance and a dominant direction (every
  /// technique): the declared lamps and environment projected to SH plus the residual estimate of
  /// the real light they do not explain, or, with nothing declared (and always for ssrt), the
  /// probeless estimate from the camera images; empty while no light is known. It is the newest
  /// when this output was collected, so with frames in flight it can come from a later input frame
  /// than this one: LightEstimate::frame_index says which (tests/technique/frame_order_test.cpp).
  std::optional<LightEstimate> light;
};

// ---------------------------------------------------------------------------------------------
// 4. Settings
// ---------------------------------------------------------------------------------------------

struct DeviceSettings {
  /// Device selector: empty = $MRGI_DEVICE, else lavapipe (llvmpipe) if present, else device 0.
  /// A number picks by index; "cpu", "lavapipe" or "llvmpipe" the first CPU device; "gpu" the
  /// first discrete GPU, else integrated, else virtual; other text the first device whose name
  /// contains it (case-insensitive).
  std::string device;
  bool validate = false;    ///< Vulkan validation layers; a message becomes an error in tests
  /// Process-wide (glibc): keep memory the driver frees at the end of a frame instead of
  /// returning it to the kernel, so a CPU driver does not page-fault its per-frame memory back
  /// in every frame (lavapipe: 2.2x faster frames; gpu/context.cpp keep_freed_memory). Costs the
  /// process its peak heap for its life. Set false where the host application tunes malloc itself.
  bool keep_freed_memory = true;
  /// Debugging: every new allocation the host can see (all of them on lavapipe) is filled with
  /// 0xff bytes (NaN as floats) instead of what the allocator had (zero pages in a fresh process,
  /// an earlier runtime's data later), so a pass that reads memory nothing wrote this frame
  /// changes the output every time instead of once in a while. Also on with MRGI_POISON_MEMORY=1.
  bool poison_memory = false;
  /// Vulkan 1.2 even where the device has 1.3: the instance asks for 1.2 and synchronization2 and
  /// dynamic rendering come from their KHR extensions, the path a 1.2 driver takes (tablets and
  /// headsets often ship one); with `validate`, a 1.3-only call is reported. For testing that path
  /// on a 1.3 device.
  bool vulkan_1_2 = false;
  /// The app's own Vulkan instance, device and queue (mrgi/vulkan_device.h): mrgi runs on them
  /// instead of creating its own (`device` is then ignored), checks that they have what it needs
  /// (BadUsage naming each missing extension and feature), waits only on its own fences and
  /// destroys none of them. Read during create_runtime only (copied). Null: mrgi's own device.
  const AppVulkanDevice* app_device = nullptr;
};

/// The frame-budget scheduler's constants (scheduler/scheduler.h says how it decides). The
/// defaults are the anchors' where they give one (Filament's dynamic resolution controller,
/// Unreal's dynamic resolution and scalability), measured on the load test otherwise
/// (perf/results/scheduler/).
struct SchedulerSettings {
  /// target = budget x (1 - headroom). Unreal takes 10 %; a CPU device shared with the app and
  /// the OS scatters its frame times more (lavapipe x2: +-25 % frame to frame, a third more under
  /// a second load), and 15 % is what held 95 % of the load test's frames within the budget in
  /// repeated runs (10 %: 94.8-95.9 %; perf/results/scheduler/README.md).
  double headroom = 0.15;
  int window_frames = 20;          ///< frames in the window of costs the controller reads (1..64)
  /// The order statistic of the window the controller holds at the target: the median (0.5,
  /// Filament's) leaves half the frames above the target, which on a device whose frame times
  /// scatter puts a fifth of them over the budget (load test); 0.95 of 20 frames, the second
  /// highest, keeps all but the tail under it. Frames over twice the window's median are left
  /// out first (Scheduler::kSpikeFactor): hiccups no resolution would have fitted.
  double quantile = 0.95;
  double dead_band_below = 0.01;   ///< no change while the quantile is within target x [1 - this,
  double dead_band_above = 0.05;   ///<   1 + this] (Filament: -1 % / +5 %)
  double scale_gain = 0.6;         ///< fraction of the model's scale correction taken per frame, down (0, 1]
  /// ... and up: slower, because a step up that overshoots costs frames over the budget and one
  /// that undershoots costs only a little resolution for a few frames.
  double scale_gain_up = 0.25;
  /// Internal-resolution factor inside a level: [min_scale, 1] (of the level's own scale: 0.5
  /// of baseline lowest's 0.5 is a quarter of the output's side).
  float min_scale = 0.5f;
  float upgrade_min_scale = 0.85f; ///< a better level is taken only if it fits at this scale or more
  int min_frames_between_changes = 30;  ///< level changes at most once a second at 30 fps
  /// A step in the load (a throttled core, a second lamp): `step_frames` consecutive frames over
  /// the budget itself drop the scale at once to min_scale, from where it climbs back at
  /// scale_gain_up (the quantile needs a twentieth of the window to move, and two frames are in
  /// flight: 4-6 frames over at each step of the load test otherwise).
  int step_frames = 2;
  int emergency_frames = 3;        ///< this many consecutive frames over
  double emergency_factor = 1.25;  ///<   this x the budget drop a level at once
};
inline constexpr int kAutoLevel = -1;

/// `technique = "auto"`: the technique is chosen at start-up by choose_technique (below), then the
/// scheduler moves inside it. One row of the table it chooses by: a technique level's sustained
/// frame time and its error against the reference, as `mrgi bench` measures them (bench.json's
/// suite aggregate) for the device at hand.
struct TechniqueFigure {
  std::string technique;
  int level = 0;
  double ms = 0.0;   ///< sustained ms per frame
  double rde = 0.0;  ///< RDE over all pixels (0 = the reference)
};
/// One quality knob set by name (technique_ladder lists a technique's knobs, units and spans).
struct KnobSetting {
  std::string name;   ///< e.g. "vpls"
  double value = 0.0;
};

/// Level "last" in the CLI resolves to technique_level_count(name) - 1.
struct RuntimeSettings {
  DeviceSettings device;
  /// baseline | dir | dlpv | dvct | ssrt, or "auto": chosen at start-up for the scene and the budget by
  /// choose_technique (with technique_table), Runtime::technique() says which.
  std::string technique = "baseline";
  std::vector<TechniqueFigure> technique_table;  ///< for "auto"; empty: the built-in table
  /// The quality level: kAutoLevel (the default) lets the scheduler choose it and the internal
  /// resolution inside it every frame to hold frame_budget_ms; 0.. fixes it (0 = the technique's
  /// best quality; the budget is then only reported, FrameStats::predicted_ms).
  int level = kAutoLevel;
  /// The frame budget, ms per frame (default: 30 fps). A frame's cost is what it takes of the
  /// device and of the host: on a CPU device (lavapipe) the two share the cores, so their sum;
  /// on a GPU the larger (FrameStats::cost_ms).
  double frame_budget_ms = 1000.0 / 30.0;
  SchedulerSettings scheduler;
  /// The scheduler's cost priors, ms per level at full internal resolution (best level first):
  /// a bench's figures for this device (`mrgi bench` bench.json). Empty: the built-in table.
  std::vector<double> level_costs_ms;
  /// Quality knobs set one by one (`--knob NAME=VALUE`): each pins that knob of the technique at
  /// every level of its ladder, from start-up (allocations follow the set ladder; a knob does not
  /// change at run time, the level does: Runtime::set_level). A knob takes values in the span its
  /// technique's ladder covers (QualityKnob::min..max; a power of two where it says so): the
  /// values the technique is built and tested for. create_runtime refuses (BadUsage naming the
  /// knob and its span) a knob the technique does not have or a value outside its span.
  std::vector<KnobSetting> knobs;
  /// Room for virtual objects added at run time (Runtime::add_object), beyond scene.json's.
  ObjectCapacity objects;
  int output_width = 0;                ///< 0 = the colour camera's width
  int output_height = 0;
  /// Camera exposure (linear radiance -> linear camera value) for albedo and the tone curve;
  /// 0 = CameraSetup::exposure (capture.json). A positive value overrides it.
  double exposure = 0.0;
  int frames_in_flight = 2;            ///< readback latency, frames (1..3)
  /// The host's readers of the camera frame (the light stage's estimates from colour and depth:
  /// probeless and residual light, an env camera's unseen prior and near-field test; the reuse
  /// tests of dir, dlpv, dvct and ssrt) take an earlier frame from the runtime's own upload
  /// buffers, at that frame's pose, instead of this frame's: the one last recorded in the frame
  /// slot this frame reuses (frames_in_flight frames earlier in a steady stream; fewer just after
  /// a priming run, which fills a slot with the frame it primes). Always so for
  /// frames given as the app's images (Runtime::process with AppInputImages), which the host never
  /// sees; set here for frames in host memory too, the two paths give the same frames value for
  /// value. A frame whose slot was not used before has no camera on the host (no estimate from
  /// colour and depth yet, an env camera's unseen part unlit, no reuse). false: this frame's
  /// images.
  bool lagged_camera_reads = false;
  /// Skip the virtual G-buffer and the technique on frames where no virtual object or its shadow
  /// can be seen (the output is then the camera frame; FrameStats::skipped says so).
  bool skip_unaffected_frames = true;
  /// A technique that shades only some tiles of the output may write their composite itself
  /// (ssrt's fast levels at the camera's size: compose then runs no pass; 10 of desk_spot's 150
  /// CPU ms per frame on lavapipe). false: the runtime's compose pass composes every frame, with
  /// the same formula (mrgi_shared.h compose_encoded); the outputs agree to 1/255 (the fused
  /// path keeps the solutions in 32-bit floats, compose reads them from RGBA16F images).
  bool fuse_compose = true;
  /// For a technique that lists no tiles of its own: compose lists the 8 x 8 output tiles where
  /// the composite can move a pixel by more than half an 8-bit level from the camera's (any
  /// technique's solutions, shaders/compose/tile_classify.comp) and composites only those, the
  /// camera frame elsewhere (dlpv fast over the suite, profiled: compose 10.8 ms -> 1.2 ms to
  /// list the tiles + 2.0 ms to composite them). false: every pixel composited; the outputs agree
  /// to 1/255 (tests/golden/test_golden_baseline.cpp: identical on the golden capture).
  bool compose_tiles = true;
  /// Ablations for research (mrgi/research.h): each technique without one of its paper's ideas.
  /// Null (the default): every technique as published.
  std::shared_ptr<const ResearchSettings> research;
  /// Profiling mode (also Runtime::set_profiling): each pass of a frame submitted on its own and
  /// waited for, timed by the host clock, so FrameStats::passes add up to the frame. Frames then
  /// do not overlap: use it to see where the time goes (bench, scheduler cost model), not to run.
  /// Needed on lavapipe, whose timestamps misattribute work between passes.
  bool profile_passes = false;
  /// The light stage's temporal filter (light estimate and environment samples): a change of the
  /// real light is followed with a time constant of this many frames (15: half a second at
  /// 30 fps), so noise between frames does not flicker the light. 0 = no filtering. 0..1e6.
  double light_lag_frames = 15.0;
  /// With declared lamps and no environment image: also estimate, from colour and depth, the
  /// real light the lamps do not explain (the room's own interreflection, daylight) and light
  /// both solutions with it as an unshadowed ambient (light/light_stage.h residual_light). The
  /// differential composite divides by the model of the real light, which without it holds the
  /// lamps' direct light only. false: the lamps alone (as before; an ablation).
  bool residual_light = true;
  /// With nothing declared (the probeless estimate from colour and depth): keep what every view
  /// showed (surface patches in world space, their transfer and colour; light/radiance_samples.h)
  /// and solve the light over all of them, so the estimate grows with the directions the camera
  /// has swept; a light change (surfaces seen again differ in brightness) drops what is out of
  /// view. false: each solve from the current view only.
  bool light_accumulate_views = true;
  /// With the views accumulated: look for a near lamp among them (light/point_lamp_fit.h) and
  /// light with it where it was found, as a shadowed lamp at its position, instead of a distant
  /// light. false: the distant light only.
  bool light_near_lamps = true;
  /// With the views accumulated: measure the real surfaces' albedo from the light they bounce
  /// onto each other (light/albedo_fit.h: a grey-world prior of 0.5 combined with what the
  /// interreflection shows), instead of assuming 0.5. The estimate's brightness and colour scale
  /// with 1 / albedo. false: the grey world.
  bool light_albedo_fit = true;
  /// With the albedo fit: the light the seen surfaces bounce onto the virtual objects is computed
  /// from them (their positions and colours) and added as ambient, and the distant light is solved
  /// without it (light/light_stage.h). false: the bounce is read as part of the distant light.
  bool light_near_field = true;
  /// With the views accumulated: where the depth frame shows no surface over a region (the sky,
  /// a window, a far wall beyond the sensor's range) its colour is the distant light from those
  /// directions and joins the solve as such, where it is above the dominant real surface (a floor's
  /// horizon; light/radiance_samples.h). false: only surfaces.
  bool light_distant_views = true;
};

// ---------------------------------------------------------------------------------------------
// 5. Devices
// ---------------------------------------------------------------------------------------------

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  std::string type;         ///< "cpu", "integrated-gpu", "discrete-gpu", ...
  std::string driver;       ///< driver name and version
  uint32_t api_version = 0;
  uint64_t device_local_mib = 0;
  bool selected = false;    ///< what mrgi would use with the given selector
};

/// Lists the Vulkan devices and marks the one `settings` would pick.
MRGI_API Expected<std::vector<DeviceInfo>> list_devices(const DeviceSettings& settings);

// ---------------------------------------------------------------------------------------------
// 6. Techniques and their quality levels
// ---------------------------------------------------------------------------------------------

struct TechniqueChoice {
  std::string technique;
  std::string reason;  ///< what was left out and why, and the figures the choice rests on
};
/// The technique for `scene` under `budget_ms`: techniques the scene cannot use are left out (no
/// lamp: the RSM-based dlpv and dir, whose bounce starts at the lamps' maps; a glossy virtual
/// material: ssrt, whose transfer is diffuse only); of the rest, the one whose most accurate level
/// that fits the budget (less the scheduler's headroom) has the lowest RDE; where none fits, the
/// one with the fastest level. `table`: a bench's figures for this device; empty: the built-in
/// table (lavapipe x2, 640x480, scheduler/technique_choice.cpp). BadInput where the scene's glTF
/// cannot be read (its materials say whether it is glossy). `glossy_objects_added`: objects added
/// at run time may be glossy (RuntimeSettings::objects.glossy), which leaves ssrt out as a
/// glossy material in scene.json does.
MRGI_API Expected<TechniqueChoice> choose_technique(const SceneDesc& scene, double budget_ms,
                                           const std::vector<TechniqueFigure>& table = {},
                                           double headroom = SchedulerSettings{}.headroom,
                                           bool glossy_objects_added = false);

/// Names of the registered techniques and their level names (best first).
MRGI_API std::vector<std::string> technique_names();
MRGI_API Expected<std::vector<std::string>> technique_levels(const std::string& technique);

/// One quality knob of a level: what it sets, its value and its unit ("virtual point lights",
/// "texels per side", ...). `mrgi info --technique NAME` prints the ladder from these.
struct QualityKnob {
  std::string name;
  double value = 0.0;
  std::string unit;
  double min = 0.0, max = 0.0;   ///< what RuntimeSettings::knobs may set it to
  bool power_of_two = false;
};
struct QualityLevelInfo {
  std::string name;
  float internal_scale = 1.0f;   ///< fraction of the output width and height the level renders at
  float mesh_error_px = 0.0f;    ///< the virtual meshes' level of detail (internal pixels; 0 = full)
  std::vector<QualityKnob> knobs;
};
/// A technique's ladder, best level first (the levels RuntimeSettings::level and
/// Runtime::set_level index), with `knobs` applied as RuntimeSettings::knobs would. NotFound for
/// an unknown technique, BadUsage for a knob it refuses.
MRGI_API Expected<std::vector<QualityLevelInfo>> technique_ladder(const std::string& technique,
                                                         const std::vector<KnobSetting>& knobs = {});

}  // namespace mrgi
