// The runtime behind mrgi::Runtime (mrgi/runtime.h): start-up (runtime_init.cpp), the frame's
// stages in their declared order (frame_stages.cpp), and the frame loop (runtime.cpp): process()
// uploads a frame, records this frame's stages, submits, and returns the frames that completed
// (pipelined over frames_in_flight slots). Everything is allocated at start-up for the
// technique's top level.
#pragma once
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/frame_constants.glsl"
#include "compose/compose.h"
#include "frame/frame_resources.h"
#include "frame/scene_gpu.h"
#include "gpu/context.h"
#include "gpu/frame_graph.h"
#include "light/light_stage.h"
#include "mrgi/runtime.h"
#include "mrgi/vulkan_device.h"
#include "recon/reconstruction.h"
#include "recon/virtual_gbuffer.h"
#include "scheduler/scheduler.h"
#include "specular/specular.h"
#include "technique/technique.h"

namespace mrgi::runtime_detail {

// A virtual surface is hidden behind a real one closer by more than this fraction of its depth.
inline constexpr float kVirtualDepthTolerance = 0.02f;

inline bool same_intrinsics(const Intrinsics& a, const Intrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy;
}

inline std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

inline double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// What a submitted frame needs to become a FrameOutput once its slot completes.
struct SlotRecord {
  bool used = false;
  int64_t frame_index = 0;
  int level = 0;
  float internal_scale = 1.0f;  // the level's internal scale x the scheduler's factor
  float scale_factor = 1.0f;    // the scheduler's factor alone
  double predicted_ms = 0.0;    // the scheduler's prediction for this frame
  bool scheduled = false;
  bool technique_ran = false;
  double record_ms = 0.0;
  // Host work for this frame in process(): checks, recording, upload, submission, without the
  // wait for an earlier frame's slot (which is that frame's device time, not this frame's work).
  double host_work_ms = 0.0;
  bool priming = false;  // a technique's priming run of this frame: its output is dropped
  // Nothing virtual in view and the output has the camera's size: the output is the camera
  // frame, converted on the host from this slot's colour upload when the frame completes.
  bool camera_copy = false;
  // The composite went to an app's image (Runtime::process with an AppOutputImage): nothing to
  // read back.
  bool app_output = false;
  bool camera_prefilled = false;  // compose::ComposeInputs::camera_prefilled
  uint64_t host_copy_bytes = 0;  // the input's upload (FrameStats::host_copy_bytes)
  // The frame whose images this slot's upload buffers hold (the last one recorded in it): what a
  // lagged camera view reads (frame/camera_view.h) when the slot comes round again.
  struct UploadedFrame {
    bool valid = false;
    int64_t index = 0;
    double timestamp = 0.0;
    glm::dmat4 camera_to_world{1.0};
  } uploaded;
  double light_ms = 0.0;
  std::vector<std::string> skipped;
  std::vector<std::string> notes;
};

class RuntimeImpl final : public Runtime {
 public:
  RuntimeImpl() = default;
  ~RuntimeImpl() override;
  Status init(const RuntimeSettings& settings, const CameraSetup& cameras, const SceneDesc& scene);

  Expected<std::vector<FrameOutput>> process(const InputFrame& frame) override {
    return process_frame(frame, nullptr, nullptr);
  }
  Expected<std::vector<FrameOutput>> process(const InputFrame& frame, const AppOutputImage& target) override;
  Expected<std::vector<FrameOutput>> process(const InputFrame& frame, const AppInputImages& images,
                                             const AppOutputImage* target) override;
  Expected<std::vector<FrameOutput>> flush() override;
  void recycle(FrameOutput&& done) override;
  const DeviceInfo& device() const override { return context_->info(); }
  const std::string& technique() const override { return technique_name_; }
  double memory_mib() const override { return context_->memory_mib(); }
  int level_count() const override { return int(technique_->levels().size()); }
  std::vector<std::string> level_names() const override;
  Status set_level(int level) override;
  Status set_frame_budget_ms(double budget_ms) override;
  Status set_profiling(bool on) override { return graph_->set_profiling(on); }
  size_t object_count() const override { return scene_gpu_->object_count(); }
  size_t lamp_count() const override { return scene_.lights.size(); }
  Status set_lamp(size_t lamp, const LightDesc& desc) override {
    MRGI_TRY(light_stage_->set_declared_lamp(lamp, desc));
    app_lamp_[lamp] = 1;  // the app's from now on: scene.json's motion stops
    keep_lamp(lamp);
    return ok_status();
  }
  bool has_object(size_t object) const override { return scene_gpu_->present(object); }
  Status set_object_visible(size_t object, bool visible) override {
    return scene_gpu_->set_visible(object, visible);
  }
  Expected<size_t> add_object(const std::string& gltf_path, const Placement& placement) override;
  Status remove_object(size_t object) override;
  Status set_object_placement(size_t object, const Placement& placement) override {
    MRGI_TRY(scene_gpu_->set_placement(object, placement));
    app_placed_[object] = 1;
    return ok_status();
  }

 private:
  Status check_validation() const;
  Status check_frame(const InputFrame& frame, const AppInputImages* images) const;
  Status check_app_images(const InputFrame& frame, const AppInputImages& images) const;
  Status check_app_output(const InputFrame& frame, const AppOutputImage& target) const;
  void write_constants(const glm::dmat4& camera_to_world);
  Expected<FrameOutput> collect(const gpu::FrameTimings& timings);
  // Waits for the frame that last used the next slot (its output joins `outputs`) and starts
  // that slot's record for `frame`.
  Expected<SlotRecord*> begin_slot(const InputFrame& frame, std::vector<FrameOutput>& outputs);
  // Records the frame's passes into the current slot and submits them.
  // `target`: the app's image the composite goes to (null: read back into host memory);
  // `images`: the app's images the frame's colour and depth come from (null: `frame`'s).
  Status record_and_submit(const InputFrame& frame, SlotRecord& rec, bool affected,
                           const AppOutputImage* target = nullptr, const AppInputImages* images = nullptr);
  Expected<std::vector<FrameOutput>> process_frame(const InputFrame& frame, const AppOutputImage* target,
                                                   const AppInputImages* images);
  // The host's view of the camera for this frame (frame/camera_view.h): this frame's images, or
  // where lagged (app images, RuntimeSettings::lagged_camera_reads) the ones the slot holds.
  frame::CameraView camera_view(const InputFrame& frame, const SlotRecord& rec, bool lagged) const;
  // The technique's priming run (Technique::Needs::estimate_from_frames): this frame run once,
  // waited for, its output dropped; the frames still in flight before it are collected into
  // `outputs`.
  Status prime(const InputFrame& frame, const AppInputImages* images, SlotRecord& rec,
               std::vector<FrameOutput>& outputs, double& prime_ms);

  // Start-up (runtime_init.cpp), in order.
  Expected<std::vector<technique::QualityLevel>> choose_technique_and_ladder(const RuntimeSettings& settings);
  Status check_settings(const RuntimeSettings& settings, size_t levels);
  void create_scheduler(const RuntimeSettings& settings, size_t levels);
  Status create_device(const RuntimeSettings& settings, const std::vector<technique::QualityLevel>& ladder);
  Status create_shared_stages(const RuntimeSettings& settings);
  Status create_solutions();
  frame::FrameResources frame_resources(const RuntimeSettings& settings) const;
  Status create_technique_stages(const RuntimeSettings& settings);

  // The frame's stages (frame_stages.cpp), recorded in the order kFrameStages lists them.
  struct FrameContext {
    const InputFrame& input;
    const frame::CameraView& camera;  // the host's view of the camera (camera_view)
    const AppInputImages* images;     // the app's images the frame comes from, or null
    SlotRecord& rec;
    bool affected;          // something virtual can be seen: the technique runs
    bool has_objects;       // a virtual object is in the scene and visible
    bool recon_used;        // the reconstruction's G-buffer is read this frame
    const technique::QualityLevel& level;
    frame::FrameInfo info;
    const AppOutputImage* target = nullptr;  // where the composite goes (null: host memory)
  };
  using FrameStage = Status (RuntimeImpl::*)(FrameContext&);
  struct FrameStageEntry {
    const char* name;
    FrameStage record;
  };
  static const FrameStageEntry kFrameStages[];
  Status record_reconstruction(FrameContext& f);
  Status update_light(FrameContext& f);
  Status record_technique_geometry(FrameContext& f);
  Status record_virtual_gbuffer(FrameContext& f);
  Status record_specular_prepare(FrameContext& f);
  Status record_technique(FrameContext& f);
  Status record_specular_finish(FrameContext& f);
  Status record_compose(FrameContext& f);
  // The composite copied into the app's image (AppOutputImage), after compose.
  Status record_app_output(FrameContext& f);
  // For a frame into an app's image on a CPU device at the camera's size: the camera frame
  // written into the slot's output words on the host (compose::ComposeInputs::camera_prefilled);
  // false where it cannot be (a Y'CbCr frame, another size, non-coherent memory).
  bool prefill_camera(const InputFrame& frame, SlotRecord& rec);

  RuntimeSettings settings_;
  CameraSetup cameras_;
  SceneDesc scene_;
  std::string technique_name_;  // the technique running (auto: the chosen one)
  std::string choice_reason_;   // why, for technique "auto"
  int output_w_ = 0, output_h_ = 0;
  int level_ = 0;       // the fixed level, or the scheduler's choice when auto_level_
  bool auto_level_ = false;
  bool warmed_up_ = false;  // the first frame's warm-up run is done (process)
  bool cpu_device_ = false;  // a CPU device (lavapipe): host and device work share the cores
  std::optional<sched::Scheduler> scheduler_;  // made at start-up whatever the level (no allocation later)
  // Declared in creation order; destroyed in reverse (the device outlives everything on it).
  std::unique_ptr<gpu::Context> context_;
  std::unique_ptr<gpu::FrameGraph> graph_;
  std::unique_ptr<frame::SceneGpu> scene_gpu_;
  std::unique_ptr<light::LightStage> light_stage_;
  std::optional<recon::Reconstruction> recon_;
  std::optional<recon::VirtualGBuffer> virtual_gbuffer_;
  gpu::BufferHandle frame_constants_;
  gpu::ImageHandle lit_rv_, lit_r_;
  const technique::TechniqueEntry* technique_entry_ = nullptr;  // the registry's, for technique_name_
  std::unique_ptr<technique::Technique> technique_;
  // Mirrors and glass (specular/specular.h); null when no virtual material is specular.
  std::unique_ptr<specular::SpecularStage> specular_;
  shader::FrameConstants constants_{};  // this frame's, as write_constants wrote them
  std::optional<compose::Compose> compose_;
  std::vector<SlotRecord> slots_;
  std::vector<FrameOutput> spare_outputs_;  // recycle(): images and masks to fill again
  glm::dmat4 last_pose_{1.0};
  bool have_pose_ = false;
  // Per virtual object: placed by the app (set_object_placement), whose placement then holds
  // instead of scene.json's motion.
  std::vector<uint8_t> app_placed_;
  std::vector<uint8_t> app_lamp_;  // lamps the app set (Runtime::set_lamp): their motion no longer applies
  // scene_.lights[i] takes the light stage's lamp i (what the influence test reads), field by
  // field: its motion keys stay, and nothing is allocated.
  void keep_lamp(size_t i) {
    const LightDesc& now = light_stage_->declared_lamp(i);
    LightDesc& l = scene_.lights[i];
    l.position = now.position;
    l.direction = now.direction;
    l.color = now.color;
    l.intensity = now.intensity;
    l.inner_angle_deg = now.inner_angle_deg;
    l.outer_angle_deg = now.outer_angle_deg;
  }
};


}  // namespace mrgi::runtime_detail
