// create_runtime: the Vulkan context, the frame graph, the uploaded scene, reconstruction, the
// virtual G-buffer, the technique and compose, all allocated once here for the technique's top
// level. process() uploads a frame, records this frame's passes, submits, and returns the frames
// that completed (pipelined over frames_in_flight slots).
#include <algorithm>
#include <cmath>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <optional>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>

#include "common/frame_constants.glsl"
#include "compose/compose.h"
#include "gpu/context.h"
#include "gpu/frame_graph.h"
#include "light/light_stage.h"
#include "mrgi/runtime.h"
#include "recon/reconstruction.h"
#include "recon/virtual_gbuffer.h"
#include "scheduler/scheduler.h"
#include "runtime/camera_math.h"
#include "runtime/influence.h"
#include "technique/scene_gpu.h"
#include "technique/technique.h"
#include "specular/specular.h"

namespace mrgi {
namespace {

using runtime_detail::opencv_projection;

// A virtual surface is hidden behind a real one closer by more than this fraction of its depth.
constexpr float kVirtualDepthTolerance = 0.02f;

bool same_intrinsics(const Intrinsics& a, const Intrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy;
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

double thread_cpu_ms() {
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
  double light_ms = 0.0;
  std::vector<std::string> skipped;
  std::vector<std::string> notes;
};

class RuntimeImpl final : public Runtime {
 public:
  RuntimeImpl() = default;
  ~RuntimeImpl() override;
  Status init(const RuntimeSettings& settings, const CameraSetup& cameras, const SceneDesc& scene);

  Expected<std::vector<FrameOutput>> process(const InputFrame& frame) override;
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
  Status set_object_visible(size_t object, bool visible) override {
    return scene_gpu_->set_visible(object, visible);
  }
  Status set_object_placement(size_t object, const Placement& placement) override {
    MRGI_TRY(scene_gpu_->set_placement(object, placement));
    app_placed_[object] = 1;
    return ok_status();
  }

 private:
  Status check_validation() const;
  Status check_frame(const InputFrame& frame) const;
  void write_constants(const glm::dmat4& camera_to_world);
  Expected<FrameOutput> collect(const gpu::FrameTimings& timings);
  // Waits for the frame that last used the next slot (its output joins `outputs`) and starts
  // that slot's record for `frame`.
  Expected<SlotRecord*> begin_slot(const InputFrame& frame, std::vector<FrameOutput>& outputs);
  // Records the frame's passes into the current slot and submits them.
  Status record_and_submit(const InputFrame& frame, SlotRecord& rec, bool affected);
  // The technique's priming run (Technique::wants_priming_run): this frame run once, waited
  // for, its output dropped; the frames still in flight before it are collected into `outputs`.
  Status prime(const InputFrame& frame, SlotRecord& rec, std::vector<FrameOutput>& outputs, double& prime_ms);

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
  std::unique_ptr<technique::SceneGpu> scene_gpu_;
  std::unique_ptr<light::LightStage> light_stage_;
  std::optional<recon::Reconstruction> recon_;
  std::optional<recon::VirtualGBuffer> virtual_gbuffer_;
  gpu::BufferHandle frame_constants_;
  gpu::ImageHandle lit_rv_, lit_r_;
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

RuntimeImpl::~RuntimeImpl() {
  if (context_ && context_->device() != VK_NULL_HANDLE) vkDeviceWaitIdle(context_->device());
  compose_.reset();
  specular_.reset();
  technique_.reset();
  light_stage_.reset();
  virtual_gbuffer_.reset();
  recon_.reset();
  scene_gpu_.reset();
  graph_.reset();
  context_.reset();
}

Status RuntimeImpl::init(const RuntimeSettings& settings, const CameraSetup& cameras,
                         const SceneDesc& scene) {
  settings_ = settings;
  cameras_ = cameras;
  scene_ = scene;
  technique_name_ = settings.technique;
  if (settings.technique == "auto") {
    for (const TechniqueFigure& f : settings.technique_table)
      if (!std::isfinite(f.ms) || f.ms <= 0.0 || !std::isfinite(f.rde) || f.rde < 0.0)
        return fail(ErrorKind::BadUsage, "RuntimeSettings.technique_table: " + f.technique + " level " +
                                             std::to_string(f.level) + ": ms must be > 0 and rde >= 0");
    auto choice = choose_technique(scene, settings.frame_budget_ms, settings.technique_table, settings.scheduler.headroom);
    if (!choice) return choice.error();
    technique_name_ = choice->technique;
    choice_reason_ = choice->reason;
    settings_.technique = technique_name_;
    // The chosen technique's own figures are the scheduler's priors.
    if (settings_.level_costs_ms.empty() && !settings.technique_table.empty()) {
      auto names = technique_levels(technique_name_);
      std::vector<double> costs(names ? names->size() : 0, 0.0);
      for (const TechniqueFigure& f : settings.technique_table)
        if (f.technique == technique_name_ && f.level >= 0 && size_t(f.level) < costs.size()) costs[size_t(f.level)] = f.ms;
      if (std::all_of(costs.begin(), costs.end(), [](double c) { return c > 0.0; })) settings_.level_costs_ms = costs;
    }
  }
  auto entry = technique::find_technique(technique_name_);
  if (!entry) return entry.error();
  auto ladder_or = (*entry)->ladder(settings.knobs);
  if (!ladder_or) return ladder_or.error();
  const std::vector<technique::QualityLevel> ladder = std::move(*ladder_or);
  if (settings.level != kAutoLevel && (settings.level < 0 || settings.level >= int(ladder.size())))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.level " + std::to_string(settings.level) +
                                         ": technique '" + settings_.technique + "' has levels 0.." +
                                         std::to_string(ladder.size() - 1) + " (or kAutoLevel)");
  MRGI_TRY(sched::check_settings(settings_, ladder.size()));
  if (settings.frames_in_flight < 1 || settings.frames_in_flight > 3)
    return fail(ErrorKind::BadUsage, "RuntimeSettings.frames_in_flight " +
                                         std::to_string(settings.frames_in_flight) + ": must be 1..3");
  if ((settings.output_width == 0) != (settings.output_height == 0) || settings.output_width < 0 ||
      settings.output_height < 0)
    return fail(ErrorKind::BadUsage, "RuntimeSettings.output_width/output_height: both 0 (the "
                                     "colour camera's size) or both positive");
  const Intrinsics& c = cameras.color;
  const Intrinsics& d = cameras.depth;
  if (c.width < 2 || c.height < 2 || d.width < 1 || d.height < 1 || !(c.fx > 0) || !(c.fy > 0) ||
      !(d.fx > 0) || !(d.fy > 0))
    return fail(ErrorKind::BadInput, "CameraSetup: colour and depth intrinsics need sizes >= 2 "
                                     "and fx, fy > 0");
  if (!(cameras.depth_scale > 0.0))
    return fail(ErrorKind::BadInput, "CameraSetup.depth_scale must be > 0 (depth units per metre)");
  if (!(cameras.exposure > 0.0))
    return fail(ErrorKind::BadInput, "CameraSetup.exposure must be > 0");
  if (!(settings.exposure >= 0.0))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.exposure must be >= 0 (0 = the camera's)");
  // The settings override the capture's exposure (e.g. a user correcting a badly exposed capture).
  if (settings.exposure > 0.0) cameras_.exposure = settings.exposure;
  output_w_ = settings.output_width ? settings.output_width : c.width;
  output_h_ = settings.output_height ? settings.output_height : c.height;
  auto_level_ = settings.level == kAutoLevel;
  {
    std::vector<double> prior = settings_.level_costs_ms.empty()
                                    ? sched::builtin_level_costs(settings_.technique, int(ladder.size()))
                                    : settings_.level_costs_ms;
    // Start at the best level the priors say fits the budget at full resolution.
    int start = int(ladder.size()) - 1;
    for (int l = 0; l < int(prior.size()); ++l)
      if (prior[size_t(l)] <= settings.frame_budget_ms * (1.0 - settings.scheduler.headroom)) {
        start = l;
        break;
      }
    scheduler_.emplace(settings.scheduler, settings.frame_budget_ms, std::move(prior), auto_level_ ? start : settings.level);
  }
  level_ = auto_level_ ? scheduler_->choice().level : settings.level;

  auto ctx = gpu::Context::create(settings.device);
  if (!ctx) return ctx.error();
  context_ = std::move(*ctx);
  cpu_device_ = context_->info().type == "cpu";
  gpu::FrameGraphSettings gs;
  gs.max_output_width = uint32_t(output_w_);
  gs.max_output_height = uint32_t(output_h_);
  gs.max_render_scale = 0.0f;
  for (const auto& l : ladder) gs.max_render_scale = std::max(gs.max_render_scale, l.internal_scale);
  gs.frames_in_flight = uint32_t(settings.frames_in_flight);
  auto graph = gpu::FrameGraph::create(*context_, gs);
  if (!graph) return graph.error();
  graph_ = std::move(*graph);
  MRGI_TRY(graph_->set_output_size(uint32_t(output_w_), uint32_t(output_h_)));
  MRGI_TRY(graph_->set_profiling(settings.profile_passes));

  auto sg = technique::SceneGpu::create(*context_, *graph_, scene_);
  if (!sg) return sg.error();
  scene_gpu_ = std::move(*sg);
  app_placed_.assign(scene_gpu_->object_count(), 0);
  app_lamp_.assign(scene_.lights.size(), 0);
  if (!(settings.light_lag_frames >= 0.0 && settings.light_lag_frames <= 1e6))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.light_lag_frames must be 0..1e6 frames");
  light::LightStageSettings ls;
  ls.estimator.lag_frames = settings.light_lag_frames;
  ls.environment.filter_frames = settings.light_lag_frames;
  ls.residual_light = settings.residual_light;
  if (!scene_gpu_->virtual_objects.empty())
    ls.focus = 0.5f * (scene_gpu_->virtual_objects.bounds_min + scene_gpu_->virtual_objects.bounds_max);
  auto stage = light::LightStage::create(ls, scene_, cameras_);
  if (!stage) return stage.error();
  light_stage_ = std::move(*stage);
  auto rc = recon::Reconstruction::create(*context_, *graph_, c, d);
  if (!rc) return rc.error();
  recon_.emplace(std::move(*rc));
  auto vg = recon::VirtualGBuffer::create(*context_, *graph_, *scene_gpu_);
  if (!vg) return vg.error();
  virtual_gbuffer_.emplace(std::move(*vg));

  auto fc = graph_->create_buffer({"frame_constants", sizeof(shader::FrameConstants),
                                   gpu::MemoryUsage::Upload, true},
                                  VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!fc) return fc.error();
  frame_constants_ = *fc;
  for (gpu::ImageHandle* h : {&lit_rv_, &lit_r_}) {
    gpu::ImageDesc desc;
    desc.name = h == &lit_rv_ ? "lit_rv" : "lit_r";
    desc.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    // lit_rv is also a colour attachment: the specular stage's caustic splat blends into it.
    const VkImageUsageFlags attachment = h == &lit_rv_ ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT : 0;
    auto img = graph_->create_image(desc, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | attachment);
    if (!img) return img.error();
    *h = *img;
  }

  compose::ComposeSettings compose_settings;
  compose_settings.classify_tiles = settings.compose_tiles;
  auto comp = compose::Compose::create(*context_, *graph_, uint32_t(output_w_), uint32_t(output_h_),
                                       output_w_ == c.width && output_h_ == c.height, compose_settings);
  if (!comp) return comp.error();
  compose_.emplace(std::move(*comp));

  technique::SharedResources shared;
  shared.context = context_.get();
  shared.knobs = settings.knobs;
  shared.dlpv_ablation = settings.dlpv_ablation;
  shared.dir_ablation = settings.dir_ablation;
  shared.graph = graph_.get();
  shared.scene = &scene_;
  shared.scene_gpu = scene_gpu_.get();
  shared.light_stage = light_stage_.get();
  shared.frame_constants = frame_constants_;
  shared.real_position = recon_->position();
  shared.real_normal = recon_->normal();
  shared.real_albedo = recon_->albedo();
  shared.virtual_position = virtual_gbuffer_->position();
  shared.virtual_normal = virtual_gbuffer_->normal();
  shared.virtual_albedo = virtual_gbuffer_->albedo();
  shared.virtual_emission = virtual_gbuffer_->emission();
  shared.lit_rv = lit_rv_;
  shared.lit_r = lit_r_;
  shared.compose_honours_tiles = true;  // record(): compose uses Technique::compose_tiles()
  // A technique that composes its own tiles would do so before the specular stage writes the
  // mirrors' and glass's pixels: with a specular material in the scene the runtime composes.
  if (settings.fuse_compose && compose_->fusable() && !(scene_gpu_->specular && !settings.specular_ablation.off)) {
    shared.composed_output = compose_->output();
  }
  shared.compose_eps = compose_->settings().eps;
  shared.compose_alpha_max = compose_->settings().alpha_max;
  shared.color_upload = recon_->color_upload();
  shared.depth_upload = recon_->depth_upload();
  shared.color_intrinsics = c;
  shared.depth_intrinsics = d;
  shared.depth_scale = cameras_.depth_scale;
  shared.depth_registered = same_intrinsics(c, d);
  auto tech = (*entry)->create(shared);
  if (!tech) return tech.error();
  technique_ = std::move(*tech);
  if (!settings.specular_ablation.off) {
    auto spec = specular::SpecularStage::create(shared, specular::settings_for(settings.specular_ablation));
    if (!spec) return spec.error();
    specular_ = std::move(*spec);
  }

  slots_.resize(size_t(settings.frames_in_flight));
  for (SlotRecord& s : slots_) {
    s.skipped.reserve(16);
    s.notes.reserve(4);
  }
  spare_outputs_.reserve(size_t(settings.frames_in_flight) + 1);  // recycle() never reallocates
  return check_validation();
}

Status RuntimeImpl::check_validation() const {
  if (!context_->validation_enabled() || context_->validation_message_count() == 0) return ok_status();
  std::string all;
  for (const std::string& m : context_->validation_messages()) all += "\n  " + m;
  return fail(ErrorKind::Device, "Vulkan validation reported " +
                                     std::to_string(context_->validation_message_count()) +
                                     " message(s):" + all);
}

Status RuntimeImpl::check_frame(const InputFrame& frame) const {
  const Intrinsics& c = cameras_.color;
  const Intrinsics& d = cameras_.depth;
  const std::string where = "frame " + std::to_string(frame.index) + ": ";
  if (frame.color.width != c.width || frame.color.height != c.height ||
      frame.color.data.size() != size_t(c.width) * c.height * 3)
    return fail(ErrorKind::BadInput, where + "colour image is " +
                                         size_text(frame.color.width, frame.color.height) +
                                         "; every frame must have the colour intrinsics' size " +
                                         size_text(c.width, c.height) + " given at set-up");
  if (frame.depth.width != d.width || frame.depth.height != d.height ||
      frame.depth.data.size() != size_t(d.width) * d.height)
    return fail(ErrorKind::BadInput, where + "depth image is " +
                                         size_text(frame.depth.width, frame.depth.height) +
                                         "; every frame must have the depth intrinsics' size " +
                                         size_text(d.width, d.height) + " given at set-up");
  return ok_status();
}

void RuntimeImpl::write_constants(const glm::dmat4& camera_to_world) {
  auto* fc = static_cast<shader::FrameConstants*>(graph_->mapped(frame_constants_, graph_->slot()));
  const VkExtent2D internal = graph_->extent(lit_rv_);
  const Intrinsics ik = cameras_.color.scaled_to(int(internal.width), int(internal.height));
  const Intrinsics ok = cameras_.color.scaled_to(output_w_, output_h_);
  const glm::mat4 c2w = glm::mat4(camera_to_world);
  const glm::mat4 w2c = glm::mat4(glm::inverse(camera_to_world));
  auto k4 = [](const Intrinsics& k) { return glm::vec4(float(k.fx), float(k.fy), float(k.cx), float(k.cy)); };
  shader::FrameConstants f{};
  f.world_to_clip = opencv_projection(ik) * w2c;
  f.camera_to_world = c2w;
  f.world_to_camera = w2c;
  f.camera_world = glm::vec4(glm::vec3(camera_to_world[3]), 1.0f);
  f.internal_k = k4(ik);
  f.output_k = k4(ok);
  f.color_k = k4(cameras_.color);
  f.depth_k = k4(cameras_.depth);
  f.internal_output_size = glm::ivec4(int(internal.width), int(internal.height), output_w_, output_h_);
  f.color_depth_size = glm::ivec4(cameras_.color.width, cameras_.color.height,
                                  cameras_.depth.width, cameras_.depth.height);
  f.camera = glm::vec4(float(cameras_.depth_scale), float(cameras_.exposure),
                       kVirtualDepthTolerance, 0.0f);
  f.flags = glm::ivec4(same_intrinsics(cameras_.color, cameras_.depth) ? 1 : 0,
                       virtual_gbuffer_->emission().valid() ? 1 : 0, 0, 0);
  *fc = f;
  constants_ = f;
}

Expected<SlotRecord*> RuntimeImpl::begin_slot(const InputFrame& frame,
                                              std::vector<FrameOutput>& outputs) {
  auto done = graph_->begin_frame();
  if (!done) return done.error();
  if (done->has_value()) {
    auto out = collect(**done);
    if (!out) return out.error();
    outputs.push_back(std::move(*out));
  }
  // The virtual objects where this frame has them: scene.json's motion at its timestamp
  // (unless the app placed the object), then the slot's vertex copy brought up to date.
  for (size_t i = 0; i < scene_.virtual_objects.size(); ++i) {
    const auto& motion = scene_.virtual_objects[i].motion;
    if (!motion.empty() && !app_placed_[i])
      MRGI_TRY(scene_gpu_->set_placement(i, placement_at(motion, frame.timestamp)));
  }
  // The lamps where scene.json's motion has them at this frame's timestamp.
  for (size_t i = 0; i < scene_.lights.size(); ++i)
    if (!scene_.lights[i].motion.empty() && !app_lamp_[i]) {
      MRGI_TRY(light_stage_->set_declared_lamp(i, lamp_at(scene_.lights[i], frame.timestamp)));
      keep_lamp(i);
    }
  scene_gpu_->commit(*graph_);
  SlotRecord& rec = slots_[graph_->slot()];
  rec.used = true;
  rec.priming = false;
  rec.camera_copy = false;
  rec.frame_index = frame.index;
  if (auto_level_) level_ = scheduler_->choice().level;
  rec.level = level_;
  rec.scheduled = auto_level_;
  rec.predicted_ms = auto_level_ ? scheduler_->choice().predicted_ms : scheduler_->predict(level_, 1.0f);
  rec.technique_ran = false;
  rec.skipped.clear();
  rec.notes.clear();
  rec.light_ms = 0.0;
  return &rec;
}

Expected<std::vector<FrameOutput>> RuntimeImpl::process(const InputFrame& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  MRGI_TRY(check_frame(frame));
  const double check_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::vector<FrameOutput> outputs;
  // begin_slot waits for the slot's earlier frame and collects it: that frame's time.
  auto slot = begin_slot(frame, outputs);
  if (!slot) return slot.error();
  SlotRecord* rec = *slot;
  auto t_work = std::chrono::steady_clock::now();

  // A frame without a pose keeps the last known one (identity before any): the output is then
  // only right for a camera that did not move; the stats say so.
  std::vector<std::string> notes;
  if (frame.pose) {
    last_pose_ = frame.pose->matrix();
    have_pose_ = true;
  } else {
    notes.push_back(have_pose_ ? "pose: none given, previous frame's pose used"
                               : "pose: none given and none before, identity used");
  }
  const bool has_objects = !scene_gpu_->virtual_objects.empty() && scene_gpu_->any_visible();
  bool affected = has_objects;
  for (const LightDesc& l : scene_.lights) affected = affected || !l.real;  // lights real surfaces
  if (affected && has_objects && settings_.skip_unaffected_frames) {
    runtime::InfluenceQuery q;
    q.box_min = scene_gpu_->virtual_objects.bounds_min;
    q.box_max = scene_gpu_->virtual_objects.bounds_max;
    q.camera_to_world = last_pose_;
    q.camera = cameras_.color;
    affected = runtime::virtual_influence_in_view(q, scene_.lights);
  }
  // The first frame that runs the technique is run twice, the first run's output dropped, when
  // the technique wants an estimate from the frames themselves (ssrt) or the scheduler chooses
  // the quality: a CPU driver compiles each pipeline's variant at its first use (lavapipe: the
  // virtual G-buffer's draw 145 ms on the sample's first frame, 6-8 ms after), which the first
  // frame would otherwise pay beyond any budget. The repeat sees the same inputs, so the
  // temporal filters and reuse caches are where one run of the frame would leave them, nearly.
  const bool warm_up = auto_level_ && !warmed_up_;
  const bool for_estimate = affected && technique_->wants_priming_run();
  if (affected && (for_estimate || warm_up)) {
    std::string note;
    warmed_up_ = true;
    // A scheduler's warm-up runs once in every slot: a slot's own buffers (uploads, readbacks)
    // are first touched by its first frame, which a CPU driver pays in page faults.
    const int runs = warm_up ? std::max(1, settings_.frames_in_flight) : 1;
    double prime_ms = 0.0;
    for (int r = 0; r < runs; ++r) {
      double ms = 0.0;
      MRGI_TRY(prime(frame, *rec, outputs, ms));
      prime_ms += ms;
      slot = begin_slot(frame, outputs);
      if (!slot) return slot.error();
      rec = *slot;
    }
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.2f", prime_ms);
    note = "technique: frame run " + std::to_string(runs + 1) + " times, the first " + std::to_string(runs) +
           " run(s) (" + ms + " ms GPU, output dropped) " +
           (for_estimate ? "primed " + technique_->name() + "'s estimate from this frame"
                         : std::string("warmed the driver up (its first use of each pipeline and of each frame slot's memory)"));
    t_work = std::chrono::steady_clock::now();  // the priming run is not this frame's own work
    notes.push_back(note);
  }
  if (!choice_reason_.empty()) {  // technique "auto": the first frame says what was chosen and why
    notes.push_back("technique: auto: " + choice_reason_);
    choice_reason_.clear();
  }
  rec->notes.insert(rec->notes.end(), notes.begin(), notes.end());
  MRGI_TRY(record_and_submit(frame, *rec, affected));
  const auto t1 = std::chrono::steady_clock::now();
  rec->record_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  rec->host_work_ms = std::max(0.0, check_ms) + std::chrono::duration<double, std::milli>(t1 - t_work).count();
  return outputs;
}

Status RuntimeImpl::prime(const InputFrame& frame, SlotRecord& rec, std::vector<FrameOutput>& outputs,
                          double& prime_ms) {
  rec.priming = true;
  MRGI_TRY(record_and_submit(frame, rec, true));
  auto all = graph_->flush();
  if (!all) return all.error();
  for (const gpu::FrameTimings& t : *all) {
    if (slots_[t.slot].priming) {
      slots_[t.slot].used = false;
      slots_[t.slot].priming = false;
      prime_ms = t.total_ms;
      continue;
    }
    auto out = collect(t);
    if (!out) return out.error();
    outputs.push_back(std::move(*out));
  }
  technique_->frames_completed();
  return ok_status();
}

// The frame skeleton, and why each full-resolution pass is there (profiled ms at 640x480 on
// lavapipe x2, baseline on desk_spot, session 5; floor pass about 1.2 ms):
//   upload            host memcpy of colour and depth into this slot's buffers (in host_ms, <1)
//   recon_warp        the temporal history warped into this frame's camera; internal resolution
//                     (0.7 at lowest's 320x240, 2.5 at high's 640x480): the merge needs it
//   recon_positions   depth decode, 3x3 same-surface median, temporal merge, positions, albedo,
//                     fused in one pass (2.5 / 7.8): every technique reads positions and albedo
//   recon_normals     normals from the positions' neighbourhood (0.7 / 2.5): a separate pass
//                     because it reads the merged positions of its neighbours
//   virtual G-buffer  raster of the virtual objects (3.9 / 5.4)
//   technique         its own passes (baseline: caster mesh, shadow maps, shading)
//   compose           the only output-resolution pass (6.0 with the composite): it writes the
//                     frame the user sees
// A frame nothing virtual affects runs no pass at all when the output has the camera's size:
// upload and a host conversion of the camera frame (below 1 floor pass); at another size
// compose's camera-copy pipeline resamples it (2-3 ms). Recon and the technique are not added.
Status RuntimeImpl::record_and_submit(const InputFrame& frame, SlotRecord& rec, bool affected) {
  const technique::QualityLevel& level = technique_->levels()[size_t(level_)];
  rec.scale_factor = auto_level_ ? scheduler_->choice().scale : 1.0f;
  rec.internal_scale = level.internal_scale * rec.scale_factor;
  MRGI_TRY(graph_->set_render_scale(rec.internal_scale));
  rec.technique_ran = affected;
  write_constants(last_pose_);
  recon_->upload(*graph_, frame);

  const bool has_objects = !scene_gpu_->virtual_objects.empty() && scene_gpu_->any_visible();
  // A frame nothing virtual affects is the camera frame (the lean skeleton above): the
  // reconstruction is not needed for it; its temporal history restarts on the next affected
  // frame (one frame of unfiltered depth).
  // The specular stage's impostors and back-projection read the reconstruction's G-buffer, so it
  // runs for a technique without one (ssrt) when a mirror or glass object is in the scene.
  const bool recon_used = technique_->uses_reconstruction() || specular_ != nullptr;
  if (affected && recon_used) {
    recon_->record(*graph_, frame_constants_);
  } else {
    recon_->skip_frame();
    rec.skipped.push_back(affected ? "recon: " + technique_->name() +
                                         " builds its own real geometry and reads the camera frame itself"
                                   : "recon: nothing virtual in view (its temporal history restarts when there is)");
  }
  if (affected) {
    // The light stage runs only where something is lit with its answer.
    // Its cost as this thread's CPU time: wall time here would count the driver's workers
    // preempting it on a CPU device; the CPU time is the work it adds to the frame.
    const double light_start = thread_cpu_ms();
    MRGI_TRY(light_stage_->update(frame, last_pose_, rec.notes));
    rec.light_ms = thread_cpu_ms() - light_start;
    technique::FrameInfo info;
    info.frame_index = frame.index;
    info.level = level_;
    info.virtual_objects_present = has_objects;
    info.camera_to_world = last_pose_;
    info.input = &frame;
    MRGI_TRY(technique_->record_geometry(info, rec.skipped));
    const std::optional<technique::RealGeometry> own = technique_->occlusion_geometry();
    if (!own && !recon_used)
      return fail(ErrorKind::Internal, technique_->name() +
                                           ": skips the reconstruction but gives no real geometry "
                                           "for the virtual objects' depth test");
    virtual_gbuffer_->record(*graph_, frame_constants_,
                             own ? *own : technique::RealGeometry{recon_->position(), recon_->position(), 1},
                             level.mesh_error_px);
    if (specular_) {
      MRGI_TRY(specular_->prepare(constants_, level_, int(technique_->levels().size()), rec.skipped));
      info.caustics = specular_->caustic_photons();
    }
    MRGI_TRY(technique_->record(info, rec.skipped));
    if (specular_) MRGI_TRY(specular_->finish(*technique_, rec.skipped));
  } else {
    rec.skipped.push_back(has_objects ? "technique: no virtual object or its shadow in view"
                                      : "technique: no virtual object and no virtual lamp in the scene");
  }
  // An unaffected frame at the camera's size needs no GPU pass at all: its output is the camera
  // frame, which the host converts from the upload buffer when the (empty) frame completes
  // (0.3 ms of host time against 2-3 ms for compose's camera-copy pass on lavapipe).
  rec.camera_copy = !affected && output_w_ == cameras_.color.width && output_h_ == cameras_.color.height;
  if (rec.camera_copy) {
    rec.skipped.push_back("compose: nothing virtual in view, the camera frame is copied on the host");
  } else {
    compose::ComposeInputs ci{frame_constants_, recon_->color_upload(), lit_rv_, lit_r_,
                              virtual_gbuffer_->position(), !affected};
    if (affected) {
      const technique::Technique::ComposeTiles tiles = technique_->compose_tiles();
      // Caustics land where the technique's tiles may not reach: then every pixel is composed.
      if (!(specular_ && specular_->lights_outside_tiles())) {
        ci.tile_args = tiles.args;
        ci.tile_list = tiles.list;
        ci.tiles_composed = tiles.composed;
      } else {
        rec.skipped.push_back("compose tiles: caustics may light pixels outside them, every pixel composed");
      }
    }
    compose_->record(*graph_, ci);
  }
  MRGI_TRY(graph_->compile());
  MRGI_TRY(graph_->submit());
  return check_validation();
}

void RuntimeImpl::recycle(FrameOutput&& done) {
  if (done.image.width != output_w_ || done.image.height != output_h_ ||
      spare_outputs_.size() > size_t(settings_.frames_in_flight))
    return;
  spare_outputs_.push_back(std::move(done));
}

Expected<FrameOutput> RuntimeImpl::collect(const gpu::FrameTimings& timings) {
  SlotRecord& rec = slots_[timings.slot];
  FrameOutput out;
  if (!spare_outputs_.empty()) {  // recycle(): its image and mask are filled below
    out.image = std::move(spare_outputs_.back().image);
    out.virtual_mask = std::move(spare_outputs_.back().virtual_mask);
    spare_outputs_.pop_back();
  }
  const auto read_start = std::chrono::steady_clock::now();
  if (rec.camera_copy) {
    const auto* rgb = static_cast<const uint8_t*>(graph_->mapped(recon_->color_upload(), timings.slot));
    compose::reuse_or_allocate(out.image, output_w_, output_h_, false);  // all written
    compose::reuse_or_allocate(out.virtual_mask, output_w_, output_h_);  // zero: no virtual pixel
    uint8_t* px = out.image.data.data();
    const size_t n = size_t(output_w_) * size_t(output_h_);
    for (size_t i = 0; i < n; ++i) {
      px[4 * i + 0] = rgb[3 * i + 0];
      px[4 * i + 1] = rgb[3 * i + 1];
      px[4 * i + 2] = rgb[3 * i + 2];
      px[4 * i + 3] = 255;
    }
  } else {
    MRGI_TRY(compose_->read(*graph_, timings.slot, out.image, out.virtual_mask));
  }
  const double readback_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start).count();
  out.stats.frame_index = rec.frame_index;
  out.stats.passes = timings.passes;
  out.stats.gpu_total_ms = timings.total_ms;
  out.stats.record_ms = rec.record_ms;
  out.stats.profiled = timings.profiled;
  out.stats.completed_s = timings.completed_s;
  out.stats.host_ms = std::max(0.0, rec.record_ms - (timings.profiled ? timings.total_ms : 0.0)) + readback_ms;
  out.stats.level = rec.level;
  out.stats.internal_scale = rec.internal_scale;
  out.stats.budget_ms = scheduler_->budget_ms();
  out.stats.predicted_ms = rec.predicted_ms;
  out.stats.scheduled = rec.scheduled;
  // The frame's cost: its device time and its own host work (the readback included); on a CPU
  // device they take turns on the same cores, on a GPU they overlap.
  const double host_work = rec.host_work_ms + readback_ms;
  out.stats.cost_ms = cpu_device_ ? timings.total_ms + host_work : std::max(timings.total_ms, host_work);
  if (!rec.priming) scheduler_->observe(rec.level, rec.scale_factor, out.stats.cost_ms, rec.technique_ran && !timings.profiled);
  out.stats.light_ms = rec.light_ms;
  out.stats.skipped = rec.skipped;
  for (const std::string& c : timings.culled) out.stats.skipped.push_back(c + ": culled (nothing reads it)");
  out.stats.notes = rec.notes;
  if (light_stage_->lighting().estimate.valid) out.light = light_stage_->lighting().estimate;
  rec.used = false;
  return out;
}

Expected<std::vector<FrameOutput>> RuntimeImpl::flush() {
  auto all = graph_->flush();
  if (!all) return all.error();
  std::vector<FrameOutput> outputs;
  for (const gpu::FrameTimings& t : *all) {
    auto out = collect(t);
    if (!out) return out.error();
    outputs.push_back(std::move(*out));
  }
  MRGI_TRY(check_validation());
  return outputs;
}

std::vector<std::string> RuntimeImpl::level_names() const {
  std::vector<std::string> names;
  for (const auto& l : technique_->levels()) names.push_back(l.name);
  return names;
}

Status RuntimeImpl::set_frame_budget_ms(double budget_ms) {
  if (!std::isfinite(budget_ms) || budget_ms <= 0.0 || budget_ms > 1e6)
    return fail(ErrorKind::BadUsage, "set_frame_budget_ms(" + std::to_string(budget_ms) + "): must be in (0, 1e6] ms");
  scheduler_->set_budget_ms(budget_ms);
  return ok_status();
}

Status RuntimeImpl::set_level(int level) {
  if (level == kAutoLevel) {
    auto_level_ = true;
    return ok_status();
  }
  auto_level_ = false;
  if (level < 0 || level >= level_count())
    return fail(ErrorKind::BadUsage, "set_level(" + std::to_string(level) + "): technique '" +
                                         technique_->name() + "' has levels 0.." +
                                         std::to_string(level_count() - 1));
  level_ = level;
  return ok_status();
}

}  // namespace

Expected<std::unique_ptr<Runtime>> create_runtime(const RuntimeSettings& settings,
                                                  const CameraSetup& cameras,
                                                  const SceneDesc& scene) {
  auto rt = std::make_unique<RuntimeImpl>();
  MRGI_TRY(rt->init(settings, cameras, scene));
  return std::unique_ptr<Runtime>(std::move(rt));
}

std::vector<std::string> technique_names() {
  std::vector<std::string> names;
  for (const auto& e : technique::registered_techniques()) names.push_back(e.name);
  return names;
}

Expected<std::vector<QualityLevelInfo>> technique_ladder(const std::string& technique,
                                                         const std::vector<KnobSetting>& knobs) {
  auto entry = technique::find_technique(technique);
  if (!entry) return entry.error();
  auto ladder = (*entry)->ladder(knobs);
  if (!ladder) return ladder.error();
  std::vector<QualityLevelInfo> out;
  for (const auto& l : *ladder) {
    QualityLevelInfo info{l.name, l.internal_scale, l.mesh_error_px, {}};
    for (const auto& k : l.knobs) info.knobs.push_back({k.name, k.value, k.unit, k.min, k.max, k.power_of_two});
    out.push_back(std::move(info));
  }
  return out;
}

Expected<std::vector<std::string>> technique_levels(const std::string& technique) {
  auto entry = technique::find_technique(technique);
  if (!entry) return entry.error();
  std::vector<std::string> names;
  auto ladder = (*entry)->ladder({});
  if (!ladder) return ladder.error();
  for (const auto& l : *ladder) names.push_back(l.name);
  return names;
}

}  // namespace mrgi
