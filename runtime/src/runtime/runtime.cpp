// The frame loop of mrgi::Runtime: per frame, wait for the slot's earlier frame and collect it,
// place the objects and lamps, check the frame, record its stages (frame_stages.cpp) and submit;
// the public functions that make a runtime and describe the techniques.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>

#include "runtime/camera_math.h"
#include "runtime/influence.h"
#include "runtime/runtime_impl.h"

namespace mrgi {
namespace runtime_detail {

RuntimeImpl::~RuntimeImpl() {
  // Only mrgi's own frames (the queue and device may be the app's, busy with its work).
  if (graph_) (void)graph_->wait_submitted();
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

Status RuntimeImpl::check_validation() const {
  if (!context_->validation_enabled() || context_->validation_message_count() == 0) return ok_status();
  std::string all;
  for (const std::string& m : context_->validation_messages()) all += "\n  " + m;
  return fail(ErrorKind::Device, "Vulkan validation reported " +
                                     std::to_string(context_->validation_message_count()) +
                                     " message(s):" + all);
}

Status RuntimeImpl::check_frame(const InputFrame& frame, const AppInputImages* images) const {
  const Intrinsics& c = cameras_.color;
  const Intrinsics& d = cameras_.depth;
  const std::string where = "frame " + std::to_string(frame.index) + ": ";
  if (images) return check_app_images(frame, *images);
  if (const std::optional<YuvImage>& yuv = frame.color_yuv) {
    const std::string field = where + "InputFrame::color_yuv: ";
    if (yuv->width != c.width || yuv->height != c.height)
      return fail(ErrorKind::BadInput, field + "image is " + size_text(yuv->width, yuv->height) +
                                           "; every frame must have the colour intrinsics' size " +
                                           size_text(c.width, c.height) + " given at set-up");
    const bool nv12 = yuv->layout == YuvImage::Layout::Nv12;
    if (!nv12 && yuv->layout != YuvImage::Layout::Yuyv)
      return fail(ErrorKind::BadInput, field + "layout is neither NV12 nor YUYV");
    if (yuv->matrix != YuvImage::Matrix::Bt601 && yuv->matrix != YuvImage::Matrix::Bt709)
      return fail(ErrorKind::BadInput, field + "matrix is neither BT.601 nor BT.709");
    if (yuv->range != YuvImage::Range::Limited && yuv->range != YuvImage::Range::Full)
      return fail(ErrorKind::BadInput, field + "range is neither limited nor full");
    if (yuv->width % 2 != 0 || (nv12 && yuv->height % 2 != 0))
      return fail(ErrorKind::BadInput, field + (nv12 ? "NV12 (4:2:0) needs an even width and height"
                                                     : "YUYV (4:2:2) needs an even width"));
    if (yuv->data.size() != yuv->expected_bytes())
      return fail(ErrorKind::BadInput, field + "holds " + std::to_string(yuv->data.size()) + " bytes; " +
                                           (nv12 ? "NV12" : "YUYV") + " at " + size_text(yuv->width, yuv->height) +
                                           " is " + std::to_string(yuv->expected_bytes()));
  } else if (frame.color.width != c.width || frame.color.height != c.height ||
             frame.color.data.size() != size_t(c.width) * c.height * 3) {
    return fail(ErrorKind::BadInput, where + "colour image is " +
                                         size_text(frame.color.width, frame.color.height) +
                                         "; every frame must have the colour intrinsics' size " +
                                         size_text(c.width, c.height) + " given at set-up");
  }
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
    if (!motion.empty() && !app_placed_[i] && scene_gpu_->present(i))
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

// The app's images are the frame's colour and depth: the frame carries none in host memory.
Status RuntimeImpl::check_app_images(const InputFrame& frame, const AppInputImages& images) const {
  const std::string where = "frame " + std::to_string(frame.index) + ": ";
  if (!context_->app_device())
    return fail(ErrorKind::BadUsage, where + "AppInputImages: the runtime was not made on the app's device "
                                             "(DeviceSettings::app_device); its images are not the runtime's to read");
  if (!frame.color.data.empty() || frame.color_yuv || !frame.depth.data.empty())
    return fail(ErrorKind::BadUsage, where + "InputFrame::color, color_yuv and depth must be empty when the frame "
                                             "is given as AppInputImages (one source for each image)");
  if (images.color == VK_NULL_HANDLE) return fail(ErrorKind::BadUsage, where + "AppInputImages::color is null");
  if (images.depth == VK_NULL_HANDLE) return fail(ErrorKind::BadUsage, where + "AppInputImages::depth is null");
  const VkFormat cf = images.color_format, df = images.depth_format;
  if (cf != VK_FORMAT_R8G8B8A8_UNORM && cf != VK_FORMAT_R8G8B8A8_SRGB && cf != VK_FORMAT_B8G8R8A8_UNORM &&
      cf != VK_FORMAT_B8G8R8A8_SRGB)
    return fail(ErrorKind::BadUsage, where + "AppInputImages::color_format must be R8G8B8A8 or B8G8R8A8, UNORM or "
                                             "SRGB (the camera's sRGB bytes), not " + std::to_string(int(cf)));
  if (df != VK_FORMAT_R16_UINT && df != VK_FORMAT_R16_UNORM && df != VK_FORMAT_D16_UNORM)
    return fail(ErrorKind::BadUsage, where + "AppInputImages::depth_format must be R16_UINT, R16_UNORM or D16_UNORM "
                                             "(16-bit depth units), not " + std::to_string(int(df)));
  for (const auto& [layout, name] : {std::pair{images.color_layout, "color_layout"}, std::pair{images.depth_layout, "depth_layout"}})
    if (layout == VK_IMAGE_LAYOUT_UNDEFINED || layout == VK_IMAGE_LAYOUT_PREINITIALIZED)
      return fail(ErrorKind::BadUsage, where + "AppInputImages::" + name +
                                               " must be the layout the image's contents are in (not UNDEFINED or "
                                               "PREINITIALIZED)");
  return ok_status();
}

Expected<std::vector<FrameOutput>> RuntimeImpl::process(const InputFrame& frame, const AppInputImages& images,
                                                        const AppOutputImage* target) {
  if (target) MRGI_TRY(check_app_output(frame, *target));
  if (target && images.wait != VK_NULL_HANDLE && images.wait == target->wait)
    return fail(ErrorKind::BadUsage, "frame " + std::to_string(frame.index) +
                                         ": AppInputImages::wait and AppOutputImage::wait are the same semaphore "
                                         "(a binary semaphore is waited for once: give one of them)");
  return process_frame(frame, target, &images);
}

Expected<std::vector<FrameOutput>> RuntimeImpl::process(const InputFrame& frame, const AppOutputImage& target) {
  MRGI_TRY(check_app_output(frame, target));
  return process_frame(frame, &target, nullptr);
}

Status RuntimeImpl::check_app_output(const InputFrame& frame, const AppOutputImage& target) const {
  const std::string where = "frame " + std::to_string(frame.index) + ": AppOutputImage::";
  if (!context_->app_device())
    return fail(ErrorKind::BadUsage, where + "image: the runtime was not made on the app's device "
                                             "(DeviceSettings::app_device); its images are not the runtime's to write");
  if (target.image == VK_NULL_HANDLE) return fail(ErrorKind::BadUsage, where + "image is null");
  if (target.format != VK_FORMAT_R8G8B8A8_UNORM && target.format != VK_FORMAT_R8G8B8A8_SRGB)
    return fail(ErrorKind::BadUsage, where + "format must be VK_FORMAT_R8G8B8A8_UNORM or _SRGB (the "
                                             "composite's bytes are copied as they are), not " +
                                             std::to_string(int(target.format)));
  if (target.final_layout == VK_IMAGE_LAYOUT_UNDEFINED || target.final_layout == VK_IMAGE_LAYOUT_PREINITIALIZED)
    return fail(ErrorKind::BadUsage, where + "final_layout must be a layout an image can be left in "
                                             "(not UNDEFINED or PREINITIALIZED)");
  return ok_status();
}

Expected<std::vector<FrameOutput>> RuntimeImpl::process_frame(const InputFrame& frame, const AppOutputImage* target,
                                                              const AppInputImages* images) {
  const auto t0 = std::chrono::steady_clock::now();
  MRGI_TRY(check_frame(frame, images));
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
  AppInputImages again;  // the app's images once a priming run below has waited for their semaphore
  const bool warm_up = auto_level_ && !warmed_up_;
  const bool for_estimate = affected && technique_->needs().estimate_from_frames && technique_->estimate_pending();
  if (affected && (for_estimate || warm_up)) {
    std::string note;
    warmed_up_ = true;
    // A scheduler's warm-up runs once in every slot: a slot's own buffers (uploads, readbacks)
    // are first touched by its first frame, which a CPU driver pays in page faults.
    const int runs = warm_up ? std::max(1, settings_.frames_in_flight) : 1;
    double prime_ms = 0.0;
    for (int r = 0; r < runs; ++r) {
      double ms = 0.0;
      MRGI_TRY(prime(frame, images, *rec, outputs, ms));
      if (images) {  // a binary semaphore is waited for once: the first run's submission did
        again = *images;
        again.wait = VK_NULL_HANDLE;
        images = &again;
      }
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
  MRGI_TRY(record_and_submit(frame, *rec, affected, target, images));
  const auto t1 = std::chrono::steady_clock::now();
  rec->record_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  rec->host_work_ms = std::max(0.0, check_ms) + std::chrono::duration<double, std::milli>(t1 - t_work).count();
  return outputs;
}

Status RuntimeImpl::prime(const InputFrame& frame, const AppInputImages* images, SlotRecord& rec,
                          std::vector<FrameOutput>& outputs, double& prime_ms) {
  rec.priming = true;
  MRGI_TRY(record_and_submit(frame, rec, true, nullptr, images));
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
  uint64_t copied = rec.host_copy_bytes;
  if (rec.app_output) {
    // Nothing comes back: the composite is in the app's image.
    out.image = ImageRGBA8();
    out.virtual_mask = Image<uint8_t, 1>();
  } else if (rec.camera_copy) {
    compose::reuse_or_allocate(out.image, output_w_, output_h_, false);  // all written
    compose::reuse_or_allocate(out.virtual_mask, output_w_, output_h_);  // zero: no virtual pixel
    compose::camera_words_to_rgba8(static_cast<const uint32_t*>(graph_->mapped(recon_->color_upload(), timings.slot)),
                                   size_t(output_w_) * size_t(output_h_), out.image.data.data());
  } else {
    MRGI_TRY(compose_->read(*graph_, timings.slot, out.image, out.virtual_mask));
  }
  if (!rec.app_output) copied += out.image.data.size() + out.virtual_mask.data.size();
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
  out.stats.host_copy_bytes = copied;
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

// An app's object: loaded in model space here, on the calling thread, then packed into the
// scene's room (SceneGpu::add_object); the slot takes no scene.json motion.
Expected<size_t> RuntimeImpl::add_object(const std::string& gltf_path, const Placement& placement) {
  auto model = load_gltf(gltf_path, Placement{});
  if (!model) return model.error();
  auto slot = scene_gpu_->add_object(*model, placement, gltf_path);
  if (!slot) return slot.error();
  app_placed_[*slot] = 1;
  return *slot;
}

Status RuntimeImpl::remove_object(size_t object) {
  MRGI_TRY(scene_gpu_->remove_object(object));
  app_placed_[object] = 1;  // scene.json's motion was its object's, not the slot's
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

}  // namespace runtime_detail

using runtime_detail::RuntimeImpl;

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
