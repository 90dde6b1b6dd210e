// The frame as a list of stages, recorded in a declared order into the frame graph, which orders
// and synchronises their passes by the resources each declares it reads and writes. What a
// technique needs of the others is its declared Technique::Needs, not a case here.
//
// The stages, and why each full-resolution pass is there (profiled ms at 640x480 on lavapipe x2,
// baseline on desk_spot; floor pass about 1.2 ms):
//   (upload)          host memcpy of colour and depth into this slot's buffers (in host_ms, <1),
//                     after the stages are recorded (a lagged camera view reads the slot's
//                     earlier frame: frame/camera_view.h); none for the app's images
//   reconstruction    camera_from_app_images and app_color_words, only for a frame given as
//                     the app's images (AppInputImages): their copy into the upload buffers;
//                     camera_yuv_to_rgb, only for a Y'CbCr colour frame (InputFrame::color_yuv)
//                     and on every such frame: its colour words, which every later reader of the
//                     camera takes; recon_warp: the temporal history warped into this frame's camera, internal
//                     resolution (0.7 at lowest's 320x240, 2.5 at high's 640x480), the merge
//                     needs it; recon_positions: depth decode, 3x3 same-surface median, temporal
//                     merge, positions, albedo, fused in one pass (2.5 / 7.8): every technique
//                     reads positions and albedo; recon_normals: normals from the positions'
//                     neighbourhood (0.7 / 2.5), a separate pass because it reads the merged
//                     positions of its neighbours
//   light             the light stage (host work: lamps, environment, estimate)
//   technique geometry  a technique's own real geometry (ssrt), for the virtual depth test
//   virtual G-buffer  raster of the virtual objects (3.9 / 5.4); below the output's size also
//                     their coverage at the output resolution (virtual_coverage), so the mask
//                     and silhouettes compose shows are the output's, not stretched texels
//   specular prepare  mirrors' and glass's impostors, back faces and caustic photons
//   technique         its own passes (baseline: the direct-light block's caster mesh, shadow
//                     maps and shading)
//   specular finish   the mirrors' and glass's pixels over the technique's solutions
//   compose           the output-resolution pass (6.0 with the composite): it writes the
//                     frame the user sees
//   app output        only for a frame into the app's image (AppOutputImage): compose's
//                     output words copied into it (a transfer, about memcpy speed on lavapipe);
//                     there the camera frame under compose's tiles is expanded on the host on a
//                     CPU device, by compose's camera pass on a GPU
// A frame nothing virtual affects runs no pass at all when the output has the camera's size
// (camera_yuv_to_rgb only, for a Y'CbCr frame): upload and a host conversion of the camera
// frame (below 1 floor pass); at another size
// compose's camera-copy pipeline resamples it (2-3 ms). Reconstruction and the technique are
// not added.
#include <string>

#include "runtime/runtime_impl.h"

namespace mrgi::runtime_detail {

const RuntimeImpl::FrameStageEntry RuntimeImpl::kFrameStages[] = {
    {"reconstruction", &RuntimeImpl::record_reconstruction},
    {"light", &RuntimeImpl::update_light},
    {"technique geometry", &RuntimeImpl::record_technique_geometry},
    {"virtual G-buffer", &RuntimeImpl::record_virtual_gbuffer},
    {"specular prepare", &RuntimeImpl::record_specular_prepare},
    {"technique", &RuntimeImpl::record_technique},
    {"specular finish", &RuntimeImpl::record_specular_finish},
    {"compose", &RuntimeImpl::record_compose},
    {"app output", &RuntimeImpl::record_app_output},
};

frame::CameraView RuntimeImpl::camera_view(const InputFrame& frame, const SlotRecord& rec, bool lagged) const {
  if (!lagged) return frame::CameraView::of(frame, last_pose_);
  frame::CameraView v;
  if (rec.uploaded.valid) {
    v = recon_->slot_view(*graph_);
    v.index = rec.uploaded.index;
    v.timestamp = rec.uploaded.timestamp;
    v.camera_to_world = rec.uploaded.camera_to_world;
  } else {  // the slot's first frame: no images yet
    v.index = frame.index;
    v.timestamp = frame.timestamp;
    v.camera_to_world = last_pose_;
  }
  v.frame_index = frame.index;
  v.frame_timestamp = frame.timestamp;
  v.env = frame.env ? &*frame.env : nullptr;
  return v;
}

// The host's copies of the frame's images into the slot's upload buffers come after the stages:
// a lagged camera view reads the images the slot held before (frame/camera_view.h).
Status RuntimeImpl::record_and_submit(const InputFrame& frame, SlotRecord& rec, bool affected,
                                      const AppOutputImage* target, const AppInputImages* images) {
  const technique::QualityLevel& level = technique_->levels()[size_t(level_)];
  rec.scale_factor = auto_level_ ? scheduler_->choice().scale : 1.0f;
  rec.internal_scale = level.internal_scale * rec.scale_factor;
  MRGI_TRY(graph_->set_render_scale(rec.internal_scale));
  rec.technique_ran = affected;
  write_constants(last_pose_);
  recon_->take_input(frame, images);
  const frame::CameraView camera = camera_view(frame, rec, images != nullptr || settings_.lagged_camera_reads);
  rec.host_copy_bytes = 0;
  rec.app_output = target != nullptr;
  // The app's colour image is expanded into the output's camera words by the pass that unpacks
  // it (recon/camera_from_app_images.cpp), on any device; a host frame's by the host on a CPU device.
  const bool camera_size = output_w_ == cameras_.color.width && output_h_ == cameras_.color.height;
  rec.camera_prefilled = target && (images ? camera_size : prefill_camera(frame, rec));

  FrameContext f{frame, camera, images, rec, affected, false, false, level, {}, target};
  f.has_objects = !scene_gpu_->virtual_objects.empty() && scene_gpu_->any_visible();
  // The specular stage's impostors and back-projection read the reconstruction's G-buffer, so it
  // runs for a technique without one (ssrt) when a mirror or glass object is in the scene.
  f.recon_used = technique_->needs().reconstruction || specular_ != nullptr;
  f.info.frame_index = frame.index;
  f.info.level = level_;
  f.info.virtual_objects_present = f.has_objects;
  f.info.camera_to_world = last_pose_;
  f.info.camera = &camera;
  for (const FrameStageEntry& stage : kFrameStages) MRGI_TRY((this->*stage.record)(f));
  rec.host_copy_bytes += recon_->copy_host_input(*graph_, frame);
  MRGI_TRY(graph_->compile());
  MRGI_TRY(graph_->submit());
  rec.uploaded = {true, frame.index, frame.timestamp, last_pose_};
  return check_validation();
}

// A frame nothing virtual affects is the camera frame (the lean frame above): the reconstruction
// is not needed for it; its temporal history restarts on the next affected frame (one frame of
// unfiltered depth).
Status RuntimeImpl::record_reconstruction(FrameContext& f) {
  MRGI_TRY(recon_->record_camera_input(*graph_, f.images && f.rec.camera_prefilled ? compose_->output()
                                                                                   : gpu::BufferHandle{}));
  if (f.affected && f.recon_used) {
    recon_->record(*graph_, frame_constants_);
    return ok_status();
  }
  recon_->skip_frame();
  f.rec.skipped.push_back(f.affected ? "recon: " + technique_->name() +
                                           " builds its own real geometry and reads the camera frame itself"
                                     : "recon: nothing virtual in view (its temporal history restarts when there is)");
  return ok_status();
}

// The light stage runs only where something is lit with its answer. Its cost as this thread's
// CPU time: wall time here would count the driver's workers preempting it on a CPU device; the
// CPU time is the work it adds to the frame.
Status RuntimeImpl::update_light(FrameContext& f) {
  if (!f.affected) return ok_status();
  const double light_start = thread_cpu_ms();
  MRGI_TRY(light_stage_->update(f.camera, f.rec.notes));
  f.rec.light_ms = thread_cpu_ms() - light_start;
  return ok_status();
}

Status RuntimeImpl::record_technique_geometry(FrameContext& f) {
  if (!f.affected) return ok_status();
  return technique_->record_geometry(f.info, f.rec.skipped);
}

Status RuntimeImpl::record_virtual_gbuffer(FrameContext& f) {
  if (!f.affected) return ok_status();
  const std::optional<frame::RealGeometry> own = technique_->occlusion_geometry();
  if (!own && !f.recon_used)
    return fail(ErrorKind::Internal, technique_->name() +
                                         ": skips the reconstruction but gives no real geometry "
                                         "for the virtual objects' depth test");
  virtual_gbuffer_->record(*graph_, frame_constants_,
                           own ? *own : frame::RealGeometry{recon_->position(), recon_->normal(), 1},
                           f.level.mesh_error_px);
  f.info.virtual_area = virtual_gbuffer_->objects_area();
  return ok_status();
}

Status RuntimeImpl::record_specular_prepare(FrameContext& f) {
  if (!f.affected || !specular_) return ok_status();
  MRGI_TRY(specular_->prepare(constants_, level_, int(technique_->levels().size()), f.rec.skipped));
  f.info.caustics = specular_->caustic_photons();
  return ok_status();
}

Status RuntimeImpl::record_technique(FrameContext& f) {
  if (f.affected) return technique_->record(f.info, f.rec.skipped);
  f.rec.skipped.push_back(f.has_objects ? "technique: no virtual object or its shadow in view"
                                        : "technique: no virtual object and no virtual lamp in the scene");
  return ok_status();
}

Status RuntimeImpl::record_specular_finish(FrameContext& f) {
  if (!f.affected || !specular_) return ok_status();
  const std::optional<shading::DirectLightOutput> direct = technique_->direct_light();
  return specular_->finish(direct ? &*direct : nullptr, f.rec.skipped);
}

// An unaffected frame at the camera's size needs no GPU pass at all: its output is the camera
// frame, which the host converts from the upload buffer when the (empty) frame completes (0.3 ms
// of host time against 2-3 ms for compose's camera-copy pass on lavapipe).
Status RuntimeImpl::record_compose(FrameContext& f) {
  f.rec.camera_copy = !f.affected && !f.target && output_w_ == cameras_.color.width && output_h_ == cameras_.color.height;
  if (f.rec.camera_copy) {
    f.rec.skipped.push_back("compose: nothing virtual in view, the camera frame is copied on the host");
    return ok_status();
  }
  compose::ComposeInputs ci{frame_constants_, recon_->color_upload(), lit_rv_, lit_r_, virtual_gbuffer_->position(),
                            !f.affected};
  ci.device_output = f.target != nullptr;
  ci.camera_prefilled = f.rec.camera_prefilled;
  ci.tile_tolerance = f.level.compose_tolerance;
  if (f.affected) {
    const technique::Technique::ComposeTiles tiles = technique_->compose_tiles();
    // Caustics land where the technique's tiles may not reach: then every pixel is composed.
    if (!(specular_ && specular_->lights_outside_tiles())) {
      ci.tile_args = tiles.args;
      ci.tile_list = tiles.list;
      ci.tiles_composed = tiles.composed;
    } else {
      f.rec.skipped.push_back("compose tiles: caustics may light pixels outside them, every pixel composed");
    }
  }
  if (f.affected) {
    ci.virtual_coverage = virtual_gbuffer_->output_coverage();
    ci.coverage_area = virtual_gbuffer_->output_coverage_area();
  }
  return compose_->record(*graph_, ci);
}

// On a CPU device the camera frame is cheaper to expand into the output's RGBA8 words on the
// host (about 0.3 ms at 640x480) than by a pass over every pixel (2-3 ms on lavapipe), the same
// trade the host path makes when it lays the camera under the tiles it reads back.
bool RuntimeImpl::prefill_camera(const InputFrame& frame, SlotRecord& rec) {
  if (!cpu_device_ || frame.color_yuv || output_w_ != cameras_.color.width || output_h_ != cameras_.color.height)
    return false;
  const gpu::GpuBuffer& out = graph_->gpu_buffer(compose_->output(), graph_->slot());
  if (!out.coherent || !out.mapped) return false;
  const size_t n = size_t(output_w_) * size_t(output_h_);
  // R | G << 8 | B << 16 words (alpha 0: no virtual pixel), as compose.comp's camera path writes
  // them: the upload's own colour words.
  recon::rgb8_to_color_words(frame.color.data.data(), n, static_cast<uint32_t*>(out.mapped));
  rec.host_copy_bytes += n * 4;
  return true;
}

// The composite into the app's image: a copy of compose's output words (RGBA8, the mask in
// alpha) at the end of the frame, the image taken from the app's layout to the one it asked for;
// the frame's submission waits for and signals the app's semaphores.
Status RuntimeImpl::record_app_output(FrameContext& f) {
  if (!f.target) return ok_status();
  const AppOutputImage target = *f.target;
  const gpu::BufferHandle words = compose_->output();
  const uint32_t w = uint32_t(output_w_), h = uint32_t(output_h_);
  const gpu::Context* ctx = context_.get();
  graph_->add_pass(
      "output_to_app_image", gpu::PassKind::Transfer,
      [words](gpu::PassBuilder& b) {
        b.read(words, gpu::Access::TransferSrc);
        b.side_effect();  // writes the app's image, outside the graph
      },
      [target, words, w, h, ctx](VkCommandBuffer cmd, gpu::PassContext& pass) {
        VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
        // Whatever the app did with the image before (on this queue) completes first.
        b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        b.oldLayout = target.old_layout;
        b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = target.image;
        b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        di.imageMemoryBarrierCount = 1;
        di.pImageMemoryBarriers = &b;
        ctx->fn().cmd_pipeline_barrier2(cmd, &di);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {w, h, 1};
        vkCmdCopyBufferToImage(cmd, pass.buffer(words), target.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
        b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.newLayout = target.final_layout;
        ctx->fn().cmd_pipeline_barrier2(cmd, &di);
      });
  MRGI_TRY(graph_->add_submit_wait(target.wait, VK_PIPELINE_STAGE_2_COPY_BIT));
  graph_->set_submit_signal(target.signal);
  return ok_status();
}

}  // namespace mrgi::runtime_detail
