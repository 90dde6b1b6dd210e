// Start-up: the technique and its ladder, the settings' checks, the scheduler, the device and
// frame graph, the shared stages (scene upload, light, reconstruction, virtual G-buffer,
// compose), the solutions, then the technique and the specular stage on the frame's resources.
#include <algorithm>
#include <cmath>
#include <string>

#include "mrgi/research.h"
#include "runtime/runtime_impl.h"

namespace mrgi::runtime_detail {

Status RuntimeImpl::init(const RuntimeSettings& settings, const CameraSetup& cameras, const SceneDesc& scene) {
  settings_ = settings;
  cameras_ = cameras;
  scene_ = scene;
  auto ladder = choose_technique_and_ladder(settings);
  if (!ladder) return ladder.error();
  MRGI_TRY(check_settings(settings, ladder->size()));
  // An environment taken from the environment camera with no such camera would light nothing,
  // silently: refused.
  if (scene.environment.present && scene.environment.from_env_camera && !cameras.env_camera)
    return fail(ErrorKind::BadUsage, "SceneDesc.environment.from_env_camera is true but CameraSetup.env_camera is "
                                     "empty: give the environment camera's model (capture.json \"env_camera\") or "
                                     "an environment image");
  // The settings override the capture's exposure (e.g. a user correcting a badly exposed capture).
  if (settings.exposure > 0.0) cameras_.exposure = settings.exposure;
  output_w_ = settings.output_width ? settings.output_width : cameras.color.width;
  output_h_ = settings.output_height ? settings.output_height : cameras.color.height;
  auto_level_ = settings.level == kAutoLevel;
  create_scheduler(settings, ladder->size());
  level_ = auto_level_ ? scheduler_->choice().level : settings.level;
  MRGI_TRY(create_device(settings, *ladder));
  MRGI_TRY(create_shared_stages(settings));
  MRGI_TRY(create_solutions());
  MRGI_TRY(create_technique_stages(settings));
  slots_.resize(size_t(settings.frames_in_flight));
  for (SlotRecord& s : slots_) {
    s.skipped.reserve(16);
    s.notes.reserve(4);
  }
  spare_outputs_.reserve(size_t(settings.frames_in_flight) + 1);  // recycle() never reallocates
  return check_validation();
}

// technique "auto": chosen for the scene and the budget (choose_technique), its own figures the
// scheduler's priors. Then the technique's ladder with the knobs applied.
Expected<std::vector<technique::QualityLevel>> RuntimeImpl::choose_technique_and_ladder(const RuntimeSettings& settings) {
  technique_name_ = settings.technique;
  if (settings.technique == "auto") {
    for (const TechniqueFigure& f : settings.technique_table)
      if (!std::isfinite(f.ms) || f.ms <= 0.0 || !std::isfinite(f.rde) || f.rde < 0.0)
        return fail(ErrorKind::BadUsage, "RuntimeSettings.technique_table: " + f.technique + " level " +
                                             std::to_string(f.level) + ": ms must be > 0 and rde >= 0");
    auto choice = choose_technique(scene_, settings.frame_budget_ms, settings.technique_table, settings.scheduler.headroom,
                                   settings.objects.glossy);
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
  technique_entry_ = *entry;
  return (*entry)->ladder(settings.knobs);
}

Status RuntimeImpl::check_settings(const RuntimeSettings& settings, size_t levels) {
  if (settings.level != kAutoLevel && (settings.level < 0 || settings.level >= int(levels)))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.level " + std::to_string(settings.level) +
                                         ": technique '" + settings_.technique + "' has levels 0.." +
                                         std::to_string(levels - 1) + " (or kAutoLevel)");
  MRGI_TRY(sched::check_settings(settings_, levels));
  if (settings.frames_in_flight < 1 || settings.frames_in_flight > 3)
    return fail(ErrorKind::BadUsage, "RuntimeSettings.frames_in_flight " +
                                         std::to_string(settings.frames_in_flight) + ": must be 1..3");
  if ((settings.output_width == 0) != (settings.output_height == 0) || settings.output_width < 0 ||
      settings.output_height < 0)
    return fail(ErrorKind::BadUsage, "RuntimeSettings.output_width/output_height: both 0 (the "
                                     "colour camera's size) or both positive");
  const Intrinsics& c = cameras_.color;
  const Intrinsics& d = cameras_.depth;
  if (c.width < 2 || c.height < 2 || d.width < 1 || d.height < 1 || !(c.fx > 0) || !(c.fy > 0) ||
      !(d.fx > 0) || !(d.fy > 0))
    return fail(ErrorKind::BadInput, "CameraSetup: colour and depth intrinsics need sizes >= 2 "
                                     "and fx, fy > 0");
  if (!(cameras_.depth_scale > 0.0))
    return fail(ErrorKind::BadInput, "CameraSetup.depth_scale must be > 0 (depth units per metre)");
  if (!(cameras_.exposure > 0.0))
    return fail(ErrorKind::BadInput, "CameraSetup.exposure must be > 0");
  if (!(settings.exposure >= 0.0))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.exposure must be >= 0 (0 = the camera's)");
  if (!(settings.light_lag_frames >= 0.0 && settings.light_lag_frames <= 1e6))
    return fail(ErrorKind::BadUsage, "RuntimeSettings.light_lag_frames must be 0..1e6 frames");
  return ok_status();
}

void RuntimeImpl::create_scheduler(const RuntimeSettings& settings, size_t levels) {
  std::vector<double> prior = settings_.level_costs_ms.empty()
                                  ? sched::builtin_level_costs(settings_.technique, int(levels))
                                  : settings_.level_costs_ms;
  // Start at the best level the priors say fits the budget at full resolution.
  int start = int(levels) - 1;
  for (int l = 0; l < int(prior.size()); ++l)
    if (prior[size_t(l)] <= settings.frame_budget_ms * (1.0 - settings.scheduler.headroom)) {
      start = l;
      break;
    }
  scheduler_.emplace(settings.scheduler, settings.frame_budget_ms, std::move(prior), auto_level_ ? start : settings.level);
}

Status RuntimeImpl::create_device(const RuntimeSettings& settings, const std::vector<technique::QualityLevel>& ladder) {
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
  return graph_->set_profiling(settings.profile_passes);
}

// The stages every technique shares: the scene's GPU meshes, the light stage, the
// reconstruction, the virtual G-buffer and compose.
Status RuntimeImpl::create_shared_stages(const RuntimeSettings& settings) {
  auto sg = frame::SceneGpu::create(*context_, *graph_, scene_, settings.objects);
  if (!sg) return sg.error();
  scene_gpu_ = std::move(*sg);
  app_placed_.assign(scene_gpu_->object_count(), 0);
  app_lamp_.assign(scene_.lights.size(), 0);
  light::LightStageSettings ls;
  ls.estimator.lag_frames = settings.light_lag_frames;
  ls.environment.filter_frames = settings.light_lag_frames;
  ls.residual_light = settings.residual_light;
  ls.samples.enabled = settings.light_accumulate_views;
  ls.point_lamp.enabled = settings.light_near_lamps;
  ls.albedo_fit.enabled = settings.light_albedo_fit;
  ls.near_field = settings.light_near_field;
  ls.samples.distant_views = settings.light_distant_views;
  if (!scene_gpu_->virtual_objects.empty())
    ls.focus = 0.5f * (scene_gpu_->virtual_objects.bounds_min + scene_gpu_->virtual_objects.bounds_max);
  auto stage = light::LightStage::create(ls, scene_, cameras_);
  if (!stage) return stage.error();
  light_stage_ = std::move(*stage);
  const Intrinsics& c = cameras_.color;
  // On the app's device frames may come as its images (AppInputImages): their staging is made.
  auto rc = recon::Reconstruction::create(*context_, *graph_, c, cameras_.depth, {}, context_->app_device());
  if (!rc) return rc.error();
  recon_.emplace(std::move(*rc));
  auto vg = recon::VirtualGBuffer::create(*context_, *graph_, *scene_gpu_);
  if (!vg) return vg.error();
  virtual_gbuffer_.emplace(std::move(*vg));
  compose::ComposeSettings compose_settings;
  compose_settings.classify_tiles = settings.compose_tiles;
  auto comp = compose::Compose::create(*context_, *graph_, uint32_t(output_w_), uint32_t(output_h_),
                                       output_w_ == c.width && output_h_ == c.height, compose_settings);
  if (!comp) return comp.error();
  compose_.emplace(std::move(*comp));
  return ok_status();
}

// The frame constants and the two solutions every technique writes.
Status RuntimeImpl::create_solutions() {
  auto fc = graph_->create_buffer({"frame_constants", sizeof(shader::FrameConstants), gpu::MemoryUsage::Upload, true},
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
  return ok_status();
}

frame::FrameResources RuntimeImpl::frame_resources(const RuntimeSettings& settings) const {
  const Intrinsics& c = cameras_.color;
  const Intrinsics& d = cameras_.depth;
  frame::FrameResources shared;
  shared.context = context_.get();
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
  // The specular stage reads the technique's solutions wherever a mirror or glass pixel's ray
  // lands (the back-projection), so with a specular material in the scene they must be defined
  // at every pixel, not only in the technique's compose tiles (ssrt's tiled levels left the rest
  // as the memory held, which made glass_mirror's frames differ from run to run); and a
  // technique that composes its own tiles would do so before the stage writes the mirrors' and
  // glass's pixels: then the runtime composes.
  const bool specular_stage = scene_gpu_->specular && !research_of(settings).specular.off;
  shared.compose_honours_tiles = !specular_stage;  // record(): compose uses Technique::compose_tiles()
  if (settings.fuse_compose && compose_->fusable() && !specular_stage) shared.composed_output = compose_->output();
  shared.compose_eps = compose_->settings().eps;
  shared.compose_alpha_max = compose_->settings().alpha_max;
  shared.color_upload = recon_->color_upload();
  shared.depth_upload = recon_->depth_upload();
  shared.color_intrinsics = c;
  shared.depth_intrinsics = d;
  shared.depth_scale = cameras_.depth_scale;
  shared.depth_registered = same_intrinsics(c, d);
  return shared;
}

// The technique (its own settings: knobs and research) and the specular stage, both on the
// frame's resources.
Status RuntimeImpl::create_technique_stages(const RuntimeSettings& settings) {
  const frame::FrameResources shared = frame_resources(settings);
  const ResearchSettings& research = research_of(settings);
  auto tech = technique_entry_->create(shared, technique::TechniqueOptions{settings.knobs, research});
  if (!tech) return tech.error();
  technique_ = std::move(*tech);
  if (!research.specular.off) {
    auto spec = specular::SpecularStage::create(shared, specular::settings_for(research.specular));
    if (!spec) return spec.error();
    specular_ = std::move(*spec);
  }
  return ok_status();
}

}  // namespace mrgi::runtime_detail
