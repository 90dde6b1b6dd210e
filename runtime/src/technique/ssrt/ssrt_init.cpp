// Ssrt::init: everything the technique allocates at start-up, for its top level (technique.h).
#include "technique/ssrt/ssrt_internal.h"

namespace mrgi::technique::ssrt_detail {

Status Ssrt::init() {
  if (!shared_.light_stage) return fail(ErrorKind::Internal, "ssrt: no light stage");
  shared_.light_stage->use_external_system();  // its transfer pass sums the system (Sec. 5.2)
  MRGI_TRY(create_geometry_stage());
  MRGI_TRY(create_sample_directions());
  MRGI_TRY(create_light_buffers());
  MRGI_TRY(create_solution_images());
  // Layouts from the shaders (gpu/reflect.h; the passes bind by name); push sizes are the C++
  // structs', checked against the shaders' declarations.
  MRGI_TRY(create_transfer_pipelines());
  MRGI_TRY(create_blur_pipelines());
  MRGI_TRY(create_shade_pipelines());
  MRGI_TRY(create_shade_tile_buffers());
  return ok_status();
}

// The paper's geometry stage (Sec. 4): its constants, the volume at the levels' largest
// resolutions, the depth filter chain, and the occluder G-buffer.
Status Ssrt::create_geometry_stage() {
  gpu::Context& ctx = *shared_.context;
  gpu::FrameGraph& graph = *shared_.graph;
  ssrt::VolumeSettings vs;
  vs.max_resolution = 1;
  vs.max_aux_resolution = 1;
  for (const SsrtLevel& l : levels_) {
    vs.max_resolution = std::max(vs.max_resolution, l.volume_resolution);
    vs.max_aux_resolution = std::max(vs.max_aux_resolution, l.aux_resolution);
  }
  auto geo_constants = graph.create_buffer(
      {"ssrt_geometry_constants", sizeof(shader::FrameConstants), gpu::MemoryUsage::Upload, true},
      VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!geo_constants) return geo_constants.error();
  geo_constants_ = *geo_constants;
  frame::FrameResources geo_shared = shared_;
  geo_shared.frame_constants = geo_constants_;
  auto vol = ssrt::Volume::create(ctx, graph, geo_shared, vs);
  if (!vol) return vol.error();
  volume_.emplace(std::move(*vol));
  auto filt = ssrt::DepthFilterGpu::create(ctx, graph, geo_shared);
  if (!filt) return filt.error();
  filter_.emplace(std::move(*filt));
  geo_position_ = filter_->position();
  geo_normal_ = filter_->normal();
  for (auto [handle, name, format] :
       {std::tuple{&occ_a_, "ssrt_occluders_a", VK_FORMAT_R32G32B32A32_UINT},
        std::tuple{&occ_b_, "ssrt_occluders_b", VK_FORMAT_R32G32_UINT}}) {
    gpu::ImageDesc od;
    od.name = name;
    od.format = format;
    auto img = graph.create_image(od, VK_IMAGE_USAGE_STORAGE_BIT);
    if (!img) return img.error();
    *handle = *img;
  }
  geo_images_ = {volume_->depth_volume(), volume_->normal_volume(), filter_->input(),
                 filter_->merged(), filter_->merged_intensity(), filter_->bilateral(),
                 filter_->final_depth(), filter_->position(), filter_->normal()};
  return ok_status();
}

Status Ssrt::create_sample_directions() {
  gpu::Context& ctx = *shared_.context;
  gpu::FrameGraph& graph = *shared_.graph;
  // Sample directions of every level, one uniform buffer (transfer.comp SampleDirections): the
  // transfer reads them at per-lane indices (the jitter set is the cell's), and lavapipe gathers
  // a uniform buffer with vector inserts but a storage buffer lane by lane in a branchy loop
  // (14 % of the transfer's sample loop).
  std::vector<glm::vec4> directions;
  for (const SsrtLevel& l : levels_) {
    auto sets = ssrt::make_sample_sets({l.directions, kSampleSeed});
    if (!sets) return sets.error();
    sample_base_.push_back(uint32_t(directions.size()));
    chi_.push_back(sets->chi);
    for (const ssrt::GpuSample& g : sets->samples) directions.push_back(g.direction_and_radius);
  }
  if (directions.size() > SSRT_MAX_SAMPLE_DIRECTIONS)
    return fail(ErrorKind::BadUsage,
                "ssrt: the levels' sample directions (4 jitter sets x N each) add up to " +
                    std::to_string(directions.size()) + ", more than the " +
                    std::to_string(SSRT_MAX_SAMPLE_DIRECTIONS) +
                    " one uniform buffer holds (SSRT_MAX_SAMPLE_DIRECTIONS, transfer_math.h)");
  directions.resize(SSRT_MAX_SAMPLE_DIRECTIONS, glm::vec4(0.0f));
  const VkDeviceSize sample_bytes = directions.size() * sizeof(glm::vec4);
  auto samples = graph.create_buffer({"ssrt_sample_directions", sample_bytes},
                                     VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!samples) return samples.error();
  samples_ = *samples;
  MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(samples_, 0), directions.data(), sample_bytes));
  return ok_status();
}

// The light the shading reads, and the transfer's sums: per-strip partials and their total,
// read back.
Status Ssrt::create_light_buffers() {
  gpu::FrameGraph& graph = *shared_.graph;
  auto light = graph.create_buffer(
      {"ssrt_light", sizeof(shader::SsrtLight), gpu::MemoryUsage::Upload, true},
      VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!light) return light.error();
  light_ = *light;

  // Everything sized for the top level: one cell per pixel of the largest internal image.
  const VkExtent2D top = graph.allocated_extent(shared_.lit_r);
  const uint32_t strips = ((top.width + kStripCells - 1) / kStripCells) * top.height;
  auto partials = graph.create_buffer(
      {"ssrt_light_partials", VkDeviceSize(strips) * kReduceEntries * sizeof(float)},
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!partials) return partials.error();
  partials_ = *partials;
  auto result = graph.create_buffer(
      {"ssrt_light_sums", kReduceEntries * sizeof(float), gpu::MemoryUsage::Readback, true},
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!result) return result.error();
  result_ = *result;
  pending_.assign(graph.frames_in_flight(), -1);
  pending_bands_.assign(graph.frames_in_flight(), 0);
  return ok_status();
}

// The transfer's coarse solution per cell and its upsampled, blurred one.
Status Ssrt::create_solution_images() {
  gpu::FrameGraph& graph = *shared_.graph;
  gpu::ImageDesc cd;
  cd.name = "ssrt_coarse";
  cd.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  cd.layers = kCoarseLayers;
  auto coarse = graph.create_image(cd, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
  if (!coarse) return coarse.error();
  coarse_ = *coarse;
  gpu::ImageDesc ud;
  ud.name = "ssrt_upsampled";
  ud.format = VK_FORMAT_R32G32B32A32_UINT;
  auto upsampled = graph.create_image(ud, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!upsampled) return upsampled.error();
  upsampled_ = *upsampled;
  return ok_status();
}

// transfer.comp's three variants, and the occluders and the sums' reductions.
Status Ssrt::create_transfer_pipelines() {
  gpu::Context& ctx = *shared_.context;
  auto transfer_spv = gpu::shader_spirv("ssrt/transfer.comp");
  if (!transfer_spv) return transfer_spv.error();
  // Variants (transfer.comp's constants kRealReceivers, kRealOnly): the general path, real
  // receivers inside the influence region, real receivers outside it.
  const struct {
    const char* name;
    uint32_t real_receivers, real_only;
    gpu::PipelineHandle* handle;
  } transfer_variants[] = {{"ssrt_transfer", 0, 0, &transfer_},
                           {"ssrt_transfer_real_receivers", 1, 0, &transfer_real_},
                           {"ssrt_transfer_real_only", 1, 1, &transfer_real_only_}};
  for (const auto& variant : transfer_variants) {
    gpu::ComputePipelineDesc d{variant.name, *transfer_spv,
                               {},
                               sizeof(TransferPush), {variant.real_receivers, variant.real_only}};
    auto tp = gpu::create_compute_pipeline(ctx, d);
    if (!tp) return tp.error();
    *variant.handle = gpu::PipelineHandle(ctx, std::move(*tp));
  }
  auto p = gpu::load_compute_pipeline(ctx, "ssrt/occluders.comp", {}, sizeof(glm::ivec4));
  if (!p) return p.error();
  occluders_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/light_reduce.comp", {}, sizeof(ReducePush));
  if (!p) return p.error();
  reduce_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/light_reduce_final.comp", {}, sizeof(FinalPush));
  if (!p) return p.error();
  reduce_final_ = std::move(*p);
  return ok_status();
}

Status Ssrt::create_blur_pipelines() {
  gpu::Context& ctx = *shared_.context;
  auto p = gpu::load_compute_pipeline(ctx, "ssrt/upsample_blur.comp", {}, sizeof(BlurPush));
  if (!p) return p.error();
  blur_ = std::move(*p);
  // One blur per window radius the ladder uses, the radius a constant (upsample_blur.comp).
  auto blur_spv = gpu::shader_spirv("ssrt/upsample_blur.comp");
  if (!blur_spv) return blur_spv.error();
  for (const SsrtLevel& level : levels_) {
    const int step = int(level.subsample);
    if (step <= 1) continue;
    const int r = blur_radius_cells(step);
    if (std::any_of(blur_by_radius_.begin(), blur_by_radius_.end(),
                    [r](const auto& e) { return e.first == r; }))
      continue;
    gpu::ComputePipelineDesc d{"ssrt_upsample_blur_r" + std::to_string(r), *blur_spv, {},
                               sizeof(BlurPush), {uint32_t(r)}};
    auto bp = gpu::create_compute_pipeline(ctx, d);
    if (!bp) return bp.error();
    blur_by_radius_.emplace_back(r, gpu::PipelineHandle(ctx, std::move(*bp)));
  }
  return ok_status();
}

// shade.comp's variants and the fast levels' tile selection.
Status Ssrt::create_shade_pipelines() {
  gpu::Context& ctx = *shared_.context;
  auto shade_spv = gpu::shader_spirv("ssrt/shade.comp");
  if (!shade_spv) return shade_spv.error();
  const struct {
    const char* name;
    uint32_t pass_through, tiled, local_x, local_y, compose;
    gpu::PipelineHandle* handle;
  } shade_variants[] = {{"ssrt_shade", 0, 0, 8, 8, 0, &shade_},
                        {"ssrt_shade_pass_through", 1, 0, 8, 8, 0, &shade_pass_},
                        {"ssrt_shade_tiled", 0, 1, 8, 1, 0, &shade_tiled_},
                        {"ssrt_shade_tiled_compose", 0, 1, 8, 1, 1, &shade_tiled_compose_}};
  // kEmission: some material emits (the virtual G-buffer has its emission target). A constant,
  // not FrameConstants::flags.y: lavapipe runs both sides of a select, so every shaded pixel
  // fetched the emission (no measurable change on the suite, but work for nothing).
  const uint32_t emission = shared_.virtual_emission.valid() ? 1u : 0u;
  for (const auto& v : shade_variants) {
    gpu::ComputePipelineDesc d{v.name, *shade_spv,
                               {},
                               sizeof(ShadePush),
                               {v.pass_through, v.tiled, v.local_x, v.local_y, v.compose, emission}};
    auto sp = gpu::create_compute_pipeline(ctx, d);
    if (!sp) return sp.error();
    *v.handle = gpu::PipelineHandle(ctx, std::move(*sp));
  }
  auto p = gpu::load_compute_pipeline(ctx, "ssrt/shade_tiles.comp", {}, sizeof(TilesPush));
  if (!p) return p.error();
  shade_tiles_ = std::move(*p);
  return ok_status();
}

// The fast levels' shade tiles: indirect dispatch arguments and tile indices.
Status Ssrt::create_shade_tile_buffers() {
  gpu::FrameGraph& graph = *shared_.graph;
  // The top level's 8 x 8 pixel tiles at most.
  const VkExtent2D top = graph.allocated_extent(shared_.lit_r);
  const uint32_t max_tiles = ((top.width + 7) / 8) * ((top.height + 7) / 8);
  auto args = graph.create_buffer({"ssrt_shade_tile_args", 16},
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                      VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!args) return args.error();
  tile_args_ = *args;
  auto list = graph.create_buffer({"ssrt_shade_tile_list", VkDeviceSize(max_tiles) * 4},
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!list) return list.error();
  tile_list_ = *list;
  // Bound as shade.comp's composed output and mask by the variants that do not compose (the
  // shader declares them; nothing is written there).
  auto unused = graph.create_buffer({"ssrt_shade_no_compose", 16}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!unused) return unused.error();
  no_compose_ = *unused;
  return ok_status();
}

}  // namespace mrgi::technique::ssrt_detail
