#include "technique/ssrt/ssrt_internal.h"

#include <array>

#include "frame/screen_bounds.h"

namespace mrgi::technique {
namespace ssrt_detail {

Status Ssrt::write_geometry_constants() {
  gpu::FrameGraph& graph = *shared_.graph;
  shader::FrameConstants fc;
  std::memcpy(&fc, graph.mapped(shared_.frame_constants, graph.slot()), sizeof(fc));
  // Texel g covers internal pixels [g s, g s + s): its centre is internal pixel g s + (s - 1)/2,
  // so u_g = (u - (s - 1)/2) / s with u = fx X/Z + cx.
  const float s = float(geometry_step_);
  const float shift = 0.5f * (s - 1.0f);
  fc.internal_k = glm::vec4(fc.internal_k.x / s, fc.internal_k.y / s, (fc.internal_k.z - shift) / s,
                            (fc.internal_k.w - shift) / s);
  const int st = int(geometry_step_);
  fc.internal_output_size.x = (fc.internal_output_size.x + st - 1) / st;
  fc.internal_output_size.y = (fc.internal_output_size.y + st - 1) / st;
  std::memcpy(graph.mapped(geo_constants_, graph.slot()), &fc, sizeof(fc));
  for (gpu::ImageHandle h : geo_images_) MRGI_TRY(graph.set_extent_divisor(h, geometry_step_));
  for (gpu::ImageHandle h : {occ_a_, occ_b_})
    MRGI_TRY(graph.set_extent_divisor(h, occluder_step_));
  return ok_status();
}

Status Ssrt::record_real_geometry(const frame::FrameInfo& info, const SsrtLevel& level,
                                  std::vector<std::string>& skipped) {
  MRGI_TRY(write_geometry_constants());
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (!volume_center_ || centred_for_layout_ != sg.layout_revision()) {
    // The workspace cube sits on the virtual objects (where occluders matter), placed when they
    // are (the first frame, an object added or removed: the volume then starts again), not as
    // they move; a scene without one keeps the cube in front of the pose of that frame.
    centred_for_layout_ = sg.layout_revision();
    if (!sg.virtual_objects.empty()) {
      volume_center_ = 0.5f * (sg.virtual_objects.bounds_min + sg.virtual_objects.bounds_max);
    } else {
      const glm::dvec4 ahead = info.camera_to_world * glm::dvec4(0.0, 0.0, kVolumeAheadM, 1.0);
      volume_center_ = glm::vec3(ahead);
    }
  }
  ssrt::VolumeFrame vf;
  vf.resolution = level.volume_resolution;
  vf.aux_resolution = level.aux_resolution;
  vf.center = *volume_center_;
  vf.camera_to_world = info.camera_to_world;
  vf.depth = info.camera && !info.camera->depth.empty() ? &info.camera->depth : nullptr;
  const LightEstimate& e = estimator().estimate();
  vf.direction_to_light = glm::vec3(e.direction_to_light[0], e.direction_to_light[1], e.direction_to_light[2]);
  MRGI_TRY(volume_->record(vf, skipped));
  return filter_->record(volume_->depth_volume(), level.final_filter, skipped,
                         geometry_step_);
}

// After the runtime waited for every frame (the priming run): all readbacks are complete, and
// are solved oldest first.
void Ssrt::frames_completed() {
  primed_ = true;
  std::vector<uint32_t> slots;
  for (uint32_t s = 0; s < pending_.size(); ++s)
    if (pending_[s] >= 0) slots.push_back(s);
  std::sort(slots.begin(), slots.end(), [&](uint32_t a, uint32_t b) { return pending_[a] < pending_[b]; });
  for (uint32_t s : slots) consume_readback(s, deferred_notes_);
}

// The sums a slot's readback holds belong to the frame that last used the slot. record() calls
// this for its own slot, whose previous frame has completed once begin_frame returned, so
// reading never stalls.
void Ssrt::consume_readback(uint32_t slot, std::vector<std::string>& notes) {
  gpu::FrameGraph& graph = *shared_.graph;
  const int64_t frame = pending_[slot];
  if (frame < 0) return;
  pending_[slot] = -1;
  const gpu::GpuBuffer& buf = graph.gpu_buffer(result_, slot);
  if (!shared_.context->invalidate(buf).ok()) {
    notes.push_back("ssrt_light_estimation: readback invalidate failed, frame not used");
    return;
  }
  const float* sums = static_cast<const float*>(graph.mapped(result_, slot));
  light::LightSystem sys;
  int k = 0;
  for (int i = 0; i < light::kMaxShCoeffs; ++i) {
    for (int j = i; j < light::kMaxShCoeffs; ++j, ++k) {
      sys.ata[i * light::kMaxShCoeffs + j] = sums[k];
      sys.ata[j * light::kMaxShCoeffs + i] = sums[k];
    }
  }
  for (int e = 0; e < light::kMaxShCoeffs * 3; ++e) sys.atb[e] = sums[136 + e];
  sys.samples = sums[184];
  // The frame clock is not in frame::FrameInfo: the filter steps by frame index; the timestamp
  // reported is the frame's index at 30 frames a second.
  const Status r = shared_.light_stage->submit_system(sys, frame, double(frame) / 30.0, pending_bands_[slot], notes);
  if (!r) notes.push_back("ssrt_light_estimation: " + r.error().message);
}

void Ssrt::write_light() {
  gpu::FrameGraph& graph = *shared_.graph;
  shader::SsrtLight l{};
  const LightEstimate& e = estimator().estimate();
  const light::ShRgb& f = estimator().filtered();
  for (int i = 0; i < 16; ++i) {
    const glm::dvec3 c = i < int(bands_ * bands_) ? f[i] : glm::dvec3(0.0);
    const double y = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    l.sh[i] = glm::vec4(float(c.x), float(c.y), float(c.z), float(y));
  }
  l.dominant = glm::vec4(e.direction_to_light[0], e.direction_to_light[1],
                         e.direction_to_light[2], 1.0f);
  l.dominant_irradiance =
      glm::vec4(e.dominant_intensity[0], e.dominant_intensity[1], e.dominant_intensity[2], 0.0f);
  std::memcpy(graph.mapped(light_, graph.slot()), &l, sizeof(l));
}

// The virtual objects' bounds grown by `grow_m` against this frame's view frustum: false when
// all eight corners lie outside one side of it; else their projection's pixel rectangle in
// pmin/pmax, and `behind` when a corner lies behind the camera (the projection is unbounded).
bool Ssrt::project_virtual_bounds(float grow_m, glm::vec2& pmin, glm::vec2& pmax,
                                  bool& behind) const {
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (sg.virtual_objects.empty()) return false;
  gpu::FrameGraph& graph = *shared_.graph;
  const auto* fc =
      static_cast<const shader::FrameConstants*>(graph.mapped(shared_.frame_constants, graph.slot()));
  const frame::ScreenBounds b = frame::project_box(*fc, sg.virtual_objects.bounds_min - glm::vec3(grow_m),
                                     sg.virtual_objects.bounds_max + glm::vec3(grow_m));
  pmin = b.min;
  pmax = b.max;
  behind = b.behind;
  return b.visible;
}

// The smallest rectangle holding both [x0, x1) x [y0, y1) rectangles (an empty one adds nothing).
static glm::ivec4 cover(glm::ivec4 a, glm::ivec4 b) {
  const bool a_empty = a.z <= a.x || a.w <= a.y, b_empty = b.z <= b.x || b.w <= b.y;
  if (a_empty) return b;
  if (b_empty) return a;
  return glm::ivec4(glm::min(glm::ivec2(a), glm::ivec2(b)), glm::max(glm::ivec2(a.z, a.w), glm::ivec2(b.z, b.w)));
}

// `outer` less `inner` as up to four disjoint rectangles (above, below, left, right; empty ones
// have x1 <= x0 or y1 <= y0). `inner` is clipped to `outer`; an empty one leaves `outer` whole.
static std::array<glm::ivec4, 4> bands_around(glm::ivec4 outer, glm::ivec4 inner) {
  inner = glm::ivec4(glm::clamp(glm::ivec2(inner), glm::ivec2(outer), glm::ivec2(outer.z, outer.w)),
                     glm::clamp(glm::ivec2(inner.z, inner.w), glm::ivec2(outer), glm::ivec2(outer.z, outer.w)));
  if (inner.z <= inner.x || inner.w <= inner.y)
    return {outer, glm::ivec4(0), glm::ivec4(0), glm::ivec4(0)};
  return {glm::ivec4(outer.x, outer.y, outer.z, inner.y), glm::ivec4(outer.x, inner.w, outer.z, outer.w),
          glm::ivec4(outer.x, inner.y, inner.x, inner.w), glm::ivec4(inner.z, inner.y, outer.z, inner.w)};
}

// The region where the virtual objects can shadow or light a real surface: their bounds grown
// by the occluder range (no receiver farther away can see a virtual occluder).
bool Ssrt::influence_in_view(glm::ivec4& cells) const {
  glm::vec2 pmin, pmax;
  bool behind = false;
  if (!project_virtual_bounds(kRangeM, pmin, pmax, behind)) return false;
  if (behind) {
    cells = glm::ivec4(0, 0, int(grid_.x), int(grid_.y));
    return true;
  }
  // Pixels -> cells (cell c covers pixels [c step, (c + 1) step)), one cell of margin.
  const float st = float(step_);
  cells = glm::ivec4(int(std::floor(pmin.x / st)) - 1, int(std::floor(pmin.y / st)) - 1,
                     int(std::ceil(pmax.x / st)) + 2, int(std::ceil(pmax.y / st)) + 2);
  cells = glm::clamp(cells, glm::ivec4(0), glm::ivec4(int(grid_.x), int(grid_.y),
                                                      int(grid_.x), int(grid_.y)));
  return true;
}

// The virtual objects' own pixels (bounds projected, one pixel of margin; empty when out of
// view, everything when a corner is behind the camera).
glm::ivec4 Ssrt::virtual_pixels() const {
  glm::vec2 pmin, pmax;
  bool behind = false;
  if (!project_virtual_bounds(0.0f, pmin, pmax, behind)) return glm::ivec4(0);
  if (behind) return glm::ivec4(0, 0, int(used_.width), int(used_.height));
  return glm::ivec4(int(std::floor(pmin.x)) - 1, int(std::floor(pmin.y)) - 1,
                    int(std::ceil(pmax.x)) + 2, int(std::ceil(pmax.y)) + 2);
}

// The cells whose receiver pixel (c step + step / 2) lies in virtual_pixels(), [x0, x1) x
// [y0, y1); an empty rectangle at (0, 0) when there is none.
glm::ivec4 Ssrt::virtual_cells() const {
  const glm::ivec4 vp = virtual_pixels();
  const float st = float(step_), half = float(step_ / 2);
  glm::ivec4 c(int(std::ceil((float(vp.x) - half) / st)), int(std::ceil((float(vp.y) - half) / st)),
               int(std::floor((float(vp.z) - 1.0f - half) / st)) + 1,
               int(std::floor((float(vp.w) - 1.0f - half) / st)) + 1);
  c = glm::clamp(c, glm::ivec4(0), glm::ivec4(int(grid_.x), int(grid_.y), int(grid_.x),
                                              int(grid_.y)));
  if (vp.z <= vp.x || vp.w <= vp.y || c.z <= c.x || c.w <= c.y) return glm::ivec4(0);
  return c;
}

void Ssrt::add_shade_pass(const char* name, ShadeMode mode, bool run_transfer) {
  gpu::FrameGraph& graph = *shared_.graph;
  const bool compose = mode == ShadeMode::TiledCompose;
  // The tiled passes rewrite some tiles of what the pass-through one wrote.
  const bool tiled = mode == ShadeMode::Tiled || compose;
  const gpu::Pipeline* pipe = compose                          ? &*shade_tiled_compose_
                              : mode == ShadeMode::Tiled       ? &*shade_tiled_
                              : mode == ShadeMode::PassThrough ? &*shade_pass_
                                                               : &*shade_;
  graph.add_shader_pass(
      name, gpu::PassKind::Compute, *pipe,
      [this, compose, tiled](gpu::ShaderPassBuilder& b) {
        const frame::FrameResources& r = shared_;
        // Bound on skipped frames too (the shader declares them, the variant may not read them).
        b.bind("coarse", coarse_);
        b.bind("real_position", geo_position_);
        b.bind("color_words", r.color_upload);
        b.bind("depth_words", r.depth_upload);
        b.bind("FrameUbo", r.frame_constants);
        b.bind("virtual_position", r.virtual_position);
        b.bind("virtual_albedo", r.virtual_albedo);
        // Without emission the albedo stands in (bound, never read: kEmission is false).
        b.bind("virtual_emission", r.virtual_emission.valid() ? r.virtual_emission : r.virtual_albedo);
        b.bind("upsampled", upsampled_);
        b.bind("Tiles", tile_list_);
        if (tiled) b.uses().read(tile_args_, gpu::Access::IndirectRead);
        // The solutions: bound by every variant, written by all but the composing one (which
        // writes the composite to the runtime's output instead; the rest get no_compose_).
        if (tiled) {
          b.bind_over("lit_rv", r.lit_rv);
          b.bind_over("lit_r", r.lit_r);
        } else {
          b.bind("lit_rv", r.lit_rv);
          b.bind("lit_r", r.lit_r);
        }
        b.bind("Output", compose ? r.composed_output : no_compose_);
      },
      [this, pipe, mode, compose, run_transfer](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const frame::FrameResources& r = shared_;
        ShadePush pc{glm::ivec4(int(grid_.x), int(grid_.y), int(step_), run_transfer ? 0 : 1),
                     glm::ivec4(int(used_.width), int(used_.height), int(geometry_step_), 0),
                     // Cells -> pixels, grown by the up-sampling footprint (Gauss radius plus
                     // the bicubic's two cells) so every pixel the filters can reach is shaded.
                     influence_pixels(),
                     glm::vec4(kIndirectTolerance, r.compose_eps, r.compose_alpha_max, 0.0f)};
        if (mode == ShadeMode::Tiled || compose) {
          gpu::dispatch_indirect(cmd, *pipe, &pc, sizeof(pc), pass.buffer(tile_args_));
        } else {
          gpu::dispatch_2d(cmd, *pipe, &pc, sizeof(pc), used_.width, used_.height);
        }
      });
}

Status Ssrt::record_geometry(const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  auto level_or = level_for(info);
  if (!level_or) return level_or.error();
  const SsrtLevel& level = **level_or;
  level_ = info.level;
  step_ = level.subsample;
  directions_ = level.directions;
  bands_ = level.sh_bands;
  geometry_step_ = level.geometry_step;
  occluder_step_ = level.occluder_step;
  gpu::FrameGraph& graph = *shared_.graph;
  used_ = graph.extent(shared_.lit_r);
  grid_ = glm::uvec2((used_.width + step_ - 1) / step_, (used_.height + step_ - 1) / step_);

  skipped.insert(skipped.end(), deferred_notes_.begin(), deferred_notes_.end());
  deferred_notes_.clear();
  consume_readback(graph.slot(), skipped);
  write_light();
  MRGI_TRY(record_real_geometry(info, level, skipped));
  geometry_frame_ = info.frame_index;
  geometry_frame_valid_ = true;
  return ok_status();
}

// The packed occluder G-buffer the transfer's samples read (occluders.comp: occ_a, occ_b).
void Ssrt::add_occluders_pass() {
  gpu::FrameGraph& graph = *shared_.graph;
  graph.add_shader_pass(
      "ssrt_occluders", gpu::PassKind::Compute, *occluders_,
      [this](gpu::ShaderPassBuilder& b) {
        const frame::FrameResources& r = shared_;
        b.bind("FrameUbo", r.frame_constants);
        b.bind("color_words", r.color_upload);
        b.bind("depth_words", r.depth_upload);
        b.bind("virtual_position", r.virtual_position);
        b.bind("virtual_normal", r.virtual_normal);
        b.bind("virtual_albedo", r.virtual_albedo);
        b.bind("real_position", geo_position_);
        b.bind("real_normal", geo_normal_);
        b.bind("occ_a", occ_a_);
        b.bind("occ_b", occ_b_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const glm::ivec4 pc(int(occluder_step_), int(used_.width), int(used_.height),
                            int(geometry_step_));
        const VkExtent2D e = pass.extent(occ_a_);
        gpu::dispatch_2d(cmd, *occluders_, &pc, sizeof(pc), e.width, e.height);
      });
}

// Three variants of one shader (the paths each does not take compiled out), with the same
// bindings: the graph pushes the descriptors for transfer_, and the other two, bound for
// their regions, have compatible layouts, so the descriptors stay.
void Ssrt::add_transfer_pass() {
  gpu::FrameGraph& graph = *shared_.graph;
  graph.add_shader_pass(
      "ssrt_transfer", gpu::PassKind::Compute, *transfer_,
      [this](gpu::ShaderPassBuilder& b) {
        const frame::FrameResources& r = shared_;
        b.bind("FrameUbo", r.frame_constants);
        b.bind("LightUbo", light_);
        b.bind("SampleDirections", samples_);
        b.bind("real_position", geo_position_);
        b.bind("real_normal", geo_normal_);
        b.bind("color_words", r.color_upload);
        b.bind("depth_words", r.depth_upload);
        b.bind("virtual_position", r.virtual_position);
        b.bind("virtual_normal", r.virtual_normal);
        b.bind("occ_a", occ_a_);
        b.bind("occ_b", occ_b_);
        b.bind("coarse", coarse_);
        b.bind("aux_position", volume_->aux_position());
        b.bind("AuxUbo", volume_->aux_views());
      },
      [this](VkCommandBuffer cmd, gpu::PassContext&) {
        const float sample_area = 3.14159265f * kRadiusM * kRadiusM / float(directions_);
        TransferPush pc{glm::ivec4(int(grid_.x), int(grid_.y), int(step_), int(directions_)),
                        glm::ivec4(int(sample_base_[size_t(level_)]), int(bands_),
                                   int(geometry_step_), int(occluder_step_)),
                        glm::vec4(kRadiusM, chi_[size_t(level_)], kNormalOffsetM, kMinSenderDistM),
                        glm::vec4(sample_area, kSaturation, kDepthBias, kRangeM),
                        influence_cells_,
                        glm::vec4(kAuxBiasTexels, 1.0f, 4.0f * 3.14159265f / float(directions_),
                                  0.0f),
                        glm::ivec4(0)};
        // Cells whose receiver may be virtual (centre pixel inside the virtual objects'
        // projected bounds) take the general path; the rest of the influence region, up to
        // four bands around them, the real-receiver one; the cells outside the region, up to
        // four bands around it, the real-only one (their real + virtual solution is the real
        // one). Each variant's shader has the paths it does not take compiled out.
        const glm::ivec4 v = virtual_cells();
        const glm::ivec4 grid(0, 0, int(grid_.x), int(grid_.y));
        const glm::ivec4 infl = cover(influence_cells_, v);
        struct Dispatch { glm::ivec4 region; const gpu::Pipeline* pipe; };
        std::array<Dispatch, 9> dispatches;
        dispatches[0] = {v, &*transfer_};
        const std::array<glm::ivec4, 4> near = bands_around(infl, v);
        const std::array<glm::ivec4, 4> far = bands_around(grid, infl);
        for (size_t i = 0; i < 4; ++i) {
          dispatches[1 + i] = {near[i], &*transfer_real_};
          dispatches[5 + i] = {far[i], &*transfer_real_only_};
        }
        for (const Dispatch& d : dispatches) {
          pc.region = d.region;
          if (pc.region.z <= pc.region.x || pc.region.w <= pc.region.y) continue;
          const gpu::Pipeline& pipe = *d.pipe;
          gpu::dispatch_2d(cmd, pipe, &pc, sizeof(pc), uint32_t(pc.region.z - pc.region.x),
                           uint32_t(pc.region.w - pc.region.y));
        }

      });
}

// The transfer's sums: per strip of cells, then their total into result_ (read back).
void Ssrt::add_light_reduce_passes() {
  gpu::FrameGraph& graph = *shared_.graph;
  const uint32_t strips_x = (grid_.x + kStripCells - 1) / kStripCells;
  const uint32_t partial_count = strips_x * grid_.y;
  graph.add_shader_pass(
      "ssrt_light_reduce", gpu::PassKind::Compute, *reduce_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("coarse", coarse_);
        b.bind("FrameUbo", shared_.frame_constants);
        b.bind("color_words", shared_.color_upload);
        b.bind("depth_words", shared_.depth_upload);
        b.bind("Partials", partials_);
      },
      [this, strips_x, partial_count](VkCommandBuffer cmd, gpu::PassContext&) {
        ReducePush pc{glm::ivec4(int(grid_.x), int(grid_.y), int(step_), int(kStripCells)),
                      glm::ivec4(int(used_.width), int(used_.height), int(strips_x), 0)};
        gpu::dispatch_2d(cmd, *reduce_, &pc, sizeof(pc), partial_count, 1, 64, 1);
      });
  graph.add_shader_pass(
      "ssrt_light_reduce_final", gpu::PassKind::Compute, *reduce_final_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("Partials", partials_);
        b.bind("Result", result_);
      },
      [this, partial_count](VkCommandBuffer cmd, gpu::PassContext&) {
        FinalPush pc{glm::ivec4(int(partial_count), 0, 0, 0)};
        gpu::dispatch_2d(cmd, *reduce_final_, &pc, sizeof(pc), kReduceEntries, 1, 24, 1);
      });
}

// The coarse solution upsampled to pixels with the blur window of the level's cell size.
void Ssrt::add_upsample_blur_pass() {
  gpu::FrameGraph& graph = *shared_.graph;
  const gpu::Pipeline* blur = &*blur_;
  for (const auto& [r, pipe] : blur_by_radius_)
    if (r == blur_radius_cells(int(step_))) blur = &*pipe;
  graph.add_shader_pass(
      "ssrt_upsample_blur", gpu::PassKind::Compute, *blur,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("coarse", coarse_);
        b.bind("upsampled", upsampled_);
      },
      [this, blur](VkCommandBuffer cmd, gpu::PassContext&) {
        BlurPush pc{glm::ivec4(int(grid_.x), int(grid_.y), int(step_), 0),
                    glm::vec4(kGaussRadiusPx, 0.0f, 0.0f, 0.0f)};
        gpu::dispatch_2d(cmd, *blur, &pc, sizeof(pc), grid_.x, grid_.y);
      });
}

// Fast levels: pass-through everywhere, then the tiles whose result can differ from it.
void Ssrt::add_tiled_shade_passes(std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  const glm::uvec2 tiles((used_.width + 7) / 8, (used_.height + 7) / 8);
  graph.add_pass(
      "ssrt_shade_tiles_clear", gpu::PassKind::Transfer,
      [this](gpu::PassBuilder& b) { b.write(tile_args_, gpu::Access::TransferDst); },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) { gpu::reset_dispatch_args(cmd, pass.buffer(tile_args_)); });
  graph.add_shader_pass(
      "ssrt_shade_tiles", gpu::PassKind::Compute, *shade_tiles_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("upsampled", upsampled_);
        b.bind("Args", tile_args_);
        b.bind("Tiles", tile_list_);
      },
      [this, tiles](VkCommandBuffer cmd, gpu::PassContext&) {
        TilesPush pc{glm::ivec4(int(grid_.x), int(grid_.y), int(step_), 0),
                     glm::ivec4(int(tiles.x), int(tiles.y), 0, 0), virtual_pixels(),
                     glm::vec4(kTileTolerance, 0.0f, 0.0f, 0.0f)};
        gpu::dispatch_2d(cmd, *shade_tiles_, &pc, sizeof(pc), tiles.x * tiles.y, 1, 64, 1);
      });
  // At the output size the tiles are the compose's too: it copies the camera frame outside
  // them, so the pass-through solutions there would never be read; at the camera's size the
  // tiled shade composes its pixels itself (shade.comp kCompose), and compose runs no pass.
  const VkExtent2D out = graph.output_size();
  const bool at_output = shared_.compose_honours_tiles && used_.width == out.width &&
                         used_.height == out.height;
  const bool fused = at_output && shared_.composed_output.valid();
  if (at_output) {
    compose_tiles_ = {tile_args_, tile_list_, fused};
    skipped.push_back("ssrt_shade: pass-through left out, compose copies the camera frame "
                      "outside the shaded tiles");
    if (fused)
      skipped.push_back("compose: ssrt_shade_tiled composes its tiles (the camera frame is laid "
                        "on the host)");
  } else {
    add_shade_pass("ssrt_shade", ShadeMode::PassThrough, true);
  }
  add_shade_pass("ssrt_shade_tiled", fused ? ShadeMode::TiledCompose : ShadeMode::Tiled, true);
}

Status Ssrt::record(const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  // Callers that drive the technique directly (tests, tools) may skip record_geometry().
  if (geometry_frame_ != info.frame_index || !geometry_frame_valid_)
    MRGI_TRY(record_geometry(info, skipped));
  geometry_frame_valid_ = false;
  gpu::FrameGraph& graph = *shared_.graph;

  const bool run_transfer = info.virtual_objects_present && influence_in_view(influence_cells_);
  if (!run_transfer) {
    const char* why = info.virtual_objects_present
                          ? "no virtual object's influence region in view"
                          : "no virtual object in the scene";
    for (const char* pass : {"ssrt_transfer", "ssrt_light_reduce", "ssrt_light_reduce_final",
                             "ssrt_upsample_blur"})
      skipped.push_back(std::string(pass) + ": " + why);
  } else {
    add_occluders_pass();
    add_transfer_pass();
    add_light_reduce_passes();
    graph.mark_output(result_);
    pending_[graph.slot()] = info.frame_index;
    pending_bands_[graph.slot()] = int(bands_);
    if (step_ > 1) {
      add_upsample_blur_pass();
    } else {
      skipped.push_back("ssrt_upsample_blur: level samples every pixel");
    }
  }
  compose_tiles_ = {};
  if (!run_transfer) {
    add_shade_pass("ssrt_shade", ShadeMode::PassThrough, false);
  } else if (step_ <= 1) {
    add_shade_pass("ssrt_shade", ShadeMode::Full, true);
  } else {
    add_tiled_shade_passes(skipped);
  }
  return ok_status();
}

}  // namespace ssrt_detail

const std::array<SsrtLevel, 4>& ssrt_levels() {
  // Full is the paper's desktop set-up (256^3, eq. 5 pass on); fast its mobile one (64^3, eq. 5
  // pass off) with the OursFast 4x4 sub-sampling; the fast levels also build the geometry
  // (ray cast, filters, G-buffer) once per transfer cell: the transfer reads its receivers at
  // the cell centres, so a finer geometry only sharpens occluder lookups, and at 640x480 on
  // lavapipe it cost 69 ms of the fast level's 219 (ray cast) plus 18 ms (filters). Their
  // auxiliary layers (occluders outside the view; the paper gives no resolution) have 32 texels
  // a side, 6 cm: at 64 their ray cast took 4.1 ms of the fast level's frame and 1.0 at 32,
  // while the suite's RDE moved by at most 0.002 (desk_spot 0.8311 -> 0.8332, corner 0.7617 ->
  // 0.7604, others within 0.0006); fastest: 3.5 -> 1.2 ms, corner 0.8126 -> 0.8203, the others
  // within 0.002.
  static const std::array<SsrtLevel, 4> levels = {{
      {"full", 1, 64, 4, 1.0f, 256, 256, true, 1, 1, 0.0f},
      {"half", 2, 32, 4, 1.0f, 256, 256, true, 1, 1, 0.0f},
      {"fast", 4, 32, 4, 1.0f, 64, 32, false, 4, 4, 0.5f},
      {"fastest", 4, 16, 4, 0.5f, 64, 32, false, 2, 1, 0.5f},
  }};
  return levels;
}

Expected<std::vector<SsrtLevel>> ssrt_levels(const std::vector<KnobSetting>& knobs) {
  return apply_knobs<SsrtLevel>("ssrt", ssrt_levels(), ssrt_detail::kSsrtKnobs, knobs);
}

Expected<std::vector<QualityLevel>> ssrt_ladder(const std::vector<KnobSetting>& knobs) {
  auto levels = ssrt_levels(knobs);
  if (!levels) return levels.error();
  return ladder_of(*levels, ssrt_levels(), ssrt_detail::kSsrtKnobs);
}

Expected<std::unique_ptr<Technique>> create_ssrt(const frame::FrameResources& shared, const TechniqueOptions& options) {
  auto levels = ssrt_levels(options.knobs);
  if (!levels) return levels.error();
  auto t = std::make_unique<ssrt_detail::Ssrt>(shared, std::move(*levels));
  MRGI_TRY(t->init());
  return std::unique_ptr<Technique>(std::move(t));
}

}  // namespace mrgi::technique
