#include "technique/dvct/dvct.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "dvct/dvct_params.glsl"
#include "gi/rsm.h"
#include "gi/voxel_light.h"
#include "gi/voxelize.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "light/light_stage.h"
#include "gi/input_reuse.h"
#include "technique/knobs.h"
#include "technique/laddered.h"
#include "light/light_set_writer.h"
#include "frame/scene_gpu.h"

namespace mrgi::technique {

const std::array<DvctLevel, 5>& dvct_levels() {
  static const std::array<DvctLevel, 5> levels = {{
      {"paper", 128, 9, true, 512, 4, 1, 1.0f, true, 0, 0.03f, 0.5f, true, 0.0f, 0.5f},
      {"high", 64, 9, true, 512, 4, 2, 1.0f, false, 0, 0.1f, 0.5f, true, 0.0f, 0.5f},
      {"medium", 64, 5, true, 256, 2, 4, 1.0f, false, 1, 0.1f, 0.5f, true, 0.0f, 0.5f},
      {"fast", 16, 3, false, 64, 1, 4, 0.5f, false, 3, 0.1f, 0.5f, false, 0.2f, 1.5f},
      {"fastest", 16, 1, false, 64, 1, 4, 0.5f, false, 3, 0.1f, 0.5f, false, 0.2f, 1.5f},
  }};
  return levels;
}

namespace {
const KnobField<DvctLevel> kDvctKnobs[] = {
    {"volume_cells", "voxels per side of each volume", &DvctLevel::volume_cells, true},
    {"diffuse_cones", "cones in the diffuse set", &DvctLevel::diffuse_cones},
    {"specular_cone", "1: a specular cone at glossy pixels", &DvctLevel::specular_cone},
    {"rsm_size", "texels per side of each reflective shadow map", &DvctLevel::rsm_size, true},
    {"rsm_lamps", "real lamps, strongest first, injected through a map pair", &DvctLevel::rsm_lamps},
    {"trace_divisor", "G-buffer pixels per traced pixel, each side (levels without shadow cones; with them every pixel)", &DvctLevel::trace_divisor},
    {"internal_scale", "fraction of the output width and height", &DvctLevel::internal_scale},
    {"shadow_cones", "1: direct light through shadow cones (paper); 0: the direct-light block's shadow maps",
     &DvctLevel::shadow_cones},
    {"baseline_level", "the direct-light block's level for the shadow maps", &DvctLevel::baseline_level},
    {"shadow_aperture", "full aperture of a shadow cone, radians", &DvctLevel::shadow_aperture},
    {"step_scale", "fraction of the touching-footprint step the cones take", &DvctLevel::step_scale},
    {"object_light", "1: the specular cone sees the objects lit by the ambient and emitting (0: the lamps' light only)",
     &DvctLevel::object_light},
    {"mesh_error_px", "largest projected error of the virtual meshes' level of detail (internal pixels; 0 = full detail)",
     &DvctLevel::mesh_error_px},
    {"compose_tolerance",
     "8-bit levels a tile's composite may move a pixel by and the tile still keep the camera frame (rounding adds up to half a level)",
     &DvctLevel::compose_tolerance},
};

// The region's side is never under this (metres): a flat or tiny object still gets room for its
// shadow and bounce (as dlpv's volume).
constexpr float kMinRegionSide = 0.25f;
// Pixels at and above this roughness trace no specular cone: the diffuse cones hold that light
// (frame::SceneGpu::kGlossyRoughness, the same line the scene's glossy flag draws).
constexpr float kSpecularRoughnessLimit = frame::SceneGpu::kGlossyRoughness;
// The narrowest specular cone (radians): a mirror reads the volume at its finest level anyway.
constexpr float kMinSpecularAperture = 0.05f;
// vct_directional_occlusion's floor for a surface seen edge-on (reconstruction noise).
constexpr float kOcclusionFloor = 0.1f;
// Levels of the environment grid's pyramid the specular cone reads (64 cells wide: down to 4,
// cells of 90 degrees, as wide as the roughest cone traced).
constexpr int kEnvLevels = 5;

}  // namespace

Expected<std::vector<DvctLevel>> dvct_levels(const std::vector<KnobSetting>& knobs) {
  auto levels = apply_knobs<DvctLevel>("dvct", dvct_levels(), kDvctKnobs, knobs);
  if (!levels) return levels;
  for (const DvctLevel& l : *levels) {
    if (l.diffuse_cones < 1) return fail(ErrorKind::BadUsage, std::string("dvct level '") + l.name + "': diffuse_cones must be >= 1");
  }
  return levels;
}

Expected<std::vector<QualityLevel>> dvct_ladder(const std::vector<KnobSetting>& knobs) {
  auto levels = dvct_levels(knobs);
  if (!levels) return levels.error();
  return ladder_of(*levels, dvct_levels(), kDvctKnobs);
}

namespace {

class Dvct final : public Laddered<DvctLevel> {
 public:
  Dvct(const frame::FrameResources& shared, std::vector<DvctLevel> levels)
      : Laddered("dvct", ladder_of(levels, dvct_levels(), kDvctKnobs), std::move(levels)),
        shared_(shared) {}
  Status init();
  Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) override;

 private:
  // The shading pipeline for (diffuse cones, specular cone), made at start-up for every level.
  using Variant = std::pair<uint32_t, bool>;
  Status record_volumes(const DvctLevel& level, const frame::FrameInfo& info, std::vector<std::string>& skipped);
  // `env_occlusion`: the block's environment occlusion, read by the shadow-cone level's shading.
  void add_cone_pass(const DvctLevel& level, const shader::DvctParams& params, bool specular,
                     gpu::ImageHandle env_occlusion);
  void record_object_light(std::vector<std::string>& skipped);
  glm::vec2 write_environment();

  frame::FrameResources shared_;
  gpu::BufferHandle lights_;  // shader::LightSet, one per frame slot (the paper level's shading)
  gpu::BufferHandle real_materials_;  // shader::DvctRealMaterials, one per frame slot
  // The light stage's environment grid and its pyramid (common/env_grid.glsl), one per frame
  // slot: what the specular cone sees where it leaves the region open.
  gpu::BufferHandle env_cells_;
  int env_width_ = 0;                    // the grid's width the buffer is sized for (0: none)
  std::vector<glm::vec4> env_scratch_;   // the pyramid before its upload (allocated at init)
  shader::DvctRealMaterials real_material_table_{};  // scene.json's regions, as the shaders read them
  std::optional<gi::ReflectiveShadowMaps> rsm_;
  std::optional<gi::Voxelizer> scene_visibility_, object_visibility_;
  std::optional<gi::VoxelLight> light_, delta_;
  // The objects' own light (ambient and emission), read by the specular cone alone
  // (DvctLevel::object_light); valid_ while it holds this frame's volumes' objects.
  std::optional<gi::VoxelLight> object_light_;
  gi::SurfaceLightSource object_surfaces_;  // what it is injected from (made at init)
  uint64_t surfaces_layout_ = 0;            // the SceneGpu::layout_revision its ranges are of
  // object_surfaces_'s ranges from the objects present now (capacity reserved at init).
  void set_object_ranges() {
    const frame::SceneGpu& sg = *shared_.scene_gpu;
    object_surfaces_.ranges.clear();
    for (const frame::DrawRange& r : sg.virtual_objects.draws)
      object_surfaces_.ranges.push_back({r.first_index, r.index_count, r.vertex_offset, r.material});
    surfaces_layout_ = sg.layout_revision();
  }
  bool object_light_valid_ = false;
  std::map<Variant, gpu::PipelineHandle> indirect_, shade_;
  gpu::ImageHandle indirect_image_;  // RGBA32UI, gi/indirect_pack.glsl
  // Direct light with shadow maps (not the shadow-cone levels), the cones' light as its screen input.
  std::unique_ptr<shading::DirectLightBlock> direct_;
  std::optional<shading::DirectLightOutput> direct_light() const override { return direct_->output(); }
  gi::InputReuse reuse_;
  struct ObjectSource {
    bool valid = false;
    uint64_t revision = 0;  // frame::SceneGpu::revision() it was voxelised at
    uint32_t cells = 0;
  } object_source_;  // what the object visibility volume holds
  bool has_virtual_ = false, glossy_ = false;
  std::vector<RealMaterialRegion> glossy_regions_;  // the real material regions the specular cone is for
  bool glossy_in_view(const frame::FrameInfo& info) const;
};

Status Dvct::init() {
  gpu::FrameGraph& graph = *shared_.graph;
  const gpu::Context& ctx = *shared_.context;
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (!shared_.light_stage) return fail(ErrorKind::Internal, "dvct: no light stage");
  auto lights = graph.create_buffer({"dvct_lights", sizeof(shader::LightSet), gpu::MemoryUsage::Upload, true},
                                    VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!lights) return lights.error();
  lights_ = *lights;
  has_virtual_ = sg.may_have_objects();
  glossy_ = sg.glossy;
  // The real material regions: a real surface with a glossy hint gets the specular cone too.
  const std::vector<RealMaterialRegion>& regions = shared_.scene->real_materials;
  if (regions.size() > DVCT_MAX_REAL_MATERIALS)
    return fail(ErrorKind::BadInput, shared_.scene->path + ": real_materials: " + std::to_string(regions.size()) +
                                         " regions; dvct reads at most " + std::to_string(DVCT_MAX_REAL_MATERIALS));
  real_material_table_.count = glm::ivec4(int(regions.size()), 0, 0, 0);
  for (size_t i = 0; i < regions.size(); ++i) {
    real_material_table_.min_roughness[i] = glm::vec4(regions[i].min, regions[i].roughness);
    real_material_table_.max_metallic[i] = glm::vec4(regions[i].max, regions[i].metallic);
    if (regions[i].roughness < frame::SceneGpu::kGlossyRoughness || regions[i].metallic > frame::SceneGpu::kGlossyMetallic)
      glossy_regions_.push_back(regions[i]);
  }
  glossy_ |= !glossy_regions_.empty();
  auto materials = graph.create_buffer({"dvct_real_materials", sizeof(shader::DvctRealMaterials), gpu::MemoryUsage::Upload, true},
                                       VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!materials) return materials.error();
  real_materials_ = *materials;
  env_width_ = shared_.light_stage->environment_grid_width();
  const size_t env_cells = std::max<size_t>(light::EnvSampler::cone_pyramid_cells(env_width_, kEnvLevels), 1);
  auto env = graph.create_buffer({"dvct environment grid", env_cells * sizeof(glm::vec4), gpu::MemoryUsage::Upload, true},
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!env) return env.error();
  env_cells_ = *env;
  env_scratch_.reserve(env_cells);
  // Without virtual objects the volumes are the smallest allowed, allocated only so the shading
  // passes bind images of the kinds they declare (mode.y 0: they read none of them).
  uint32_t cells = 2, rsm_size = 16;
  if (has_virtual_)
    for (const DvctLevel& l : levels_) {
      cells = std::max(cells, l.volume_cells);
      rsm_size = std::max(rsm_size, l.rsm_size);
    }
  auto visibility = [&](const char* name) -> Status {
    gi::VoxelizeSettings s;
    s.name = name;
    s.resolution = cells;
    auto v = gi::Voxelizer::create(graph, s);
    if (!v) return v.error();
    (std::string(name) == "dvct scene" ? scene_visibility_ : object_visibility_).emplace(std::move(*v));
    return ok_status();
  };
  MRGI_TRY(visibility("dvct scene"));
  MRGI_TRY(visibility("dvct objects"));
  for (int k = 0; k < 2; ++k) {
    gi::VoxelLightSettings s;
    s.name = k == 0 ? "dvct light" : "dvct delta";
    s.resolution = cells;
    auto v = gi::VoxelLight::create(graph, s);
    if (!v) return v.error();
    (k == 0 ? light_ : delta_).emplace(std::move(*v));
  }
  {
    gi::VoxelLightSettings s;
    s.name = "dvct object light";
    // Only the specular cone reads it: without a glossy material in the scene it is never
    // injected, and the smallest volume stands in for the binding.
    s.resolution = glossy_ ? cells : 2;
    s.surfaces = has_virtual_ && glossy_;
    auto v = gi::VoxelLight::create(graph, s);
    if (!v) return v.error();
    object_light_.emplace(std::move(*v));
    object_surfaces_.vertices = sg.virtual_objects.vertices;
    object_surfaces_.indices = sg.virtual_objects.indices;
    object_surfaces_.materials = sg.materials;
    object_surfaces_.base_color_maps = sg.base_color_maps;
    object_surfaces_.light_set = lights_;
    object_surfaces_.emission = sg.emissive;
    object_surfaces_.ranges.reserve(sg.virtual_objects.draws.capacity());
    set_object_ranges();
  }
  if (has_virtual_) {
    gi::RsmSettings rs;
    rs.name = "dvct rsm";
    rs.size = rsm_size;
    auto rsm = gi::ReflectiveShadowMaps::create(graph, sg, {shared_.real_position, shared_.real_normal, shared_.real_albedo}, rs);
    if (!rsm) return rsm.error();
    rsm_.emplace(std::move(*rsm));
  }
  // A level with the specular cone also gets the variant without it, for frames with no glossy
  // material in view: lavapipe runs every path of a shader, so it is compiled out, not skipped.
  for (const DvctLevel& l : levels_)
    for (const bool specular : {l.specular_cone, false}) {
      const Variant key{l.diffuse_cones, specular};
      auto& table = l.shadow_cones ? shade_ : indirect_;
      if (table.count(key)) continue;
      const char* shader = l.shadow_cones ? "dvct/shade.comp" : "dvct/indirect.comp";
      auto spv = gpu::shader_spirv(shader);
      if (!spv) return spv.error();
      auto p = gpu::create_compute_pipeline(
          ctx, {std::string("dvct_") + (l.shadow_cones ? "shade_" : "indirect_") + std::to_string(l.diffuse_cones) +
                    (specular ? "_specular" : ""),
                *spv, {}, sizeof(shader::DvctParams), {l.diffuse_cones, specular ? 1u : 0u}});
      if (!p) return p.error();
      table.emplace(key, gpu::PipelineHandle(ctx, std::move(*p)));
    }
  gpu::ImageDesc d;
  d.name = "dvct indirect";
  d.format = VK_FORMAT_R32G32B32A32_UINT;
  auto indirect = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!indirect) return indirect.error();
  indirect_image_ = *indirect;
  reuse_.reserve(size_t(shared_.depth_intrinsics.width) * size_t(shared_.depth_intrinsics.height), shared_.depth_scale);
  shading::DirectLightOptions direct;
  direct.screen_indirect = true;
  auto block = shading::DirectLightBlock::create(shared_, direct);
  if (!block) return block.error();
  direct_ = std::move(*block);
  return ok_status();
}

// The four volumes for this frame: voxelised and injected, or kept from the frame that made them.
Status Dvct::record_volumes(const DvctLevel& level, const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  gpu::FrameGraph& graph = *shared_.graph;
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  MRGI_TRY(scene_visibility_->set_cells(graph, level.volume_cells));
  MRGI_TRY(object_visibility_->set_cells(graph, level.volume_cells));
  MRGI_TRY(light_->set_cells(graph, level.volume_cells));
  MRGI_TRY(delta_->set_cells(graph, level.volume_cells));
  if (glossy_) MRGI_TRY(object_light_->set_cells(graph, level.volume_cells));
  const gi::VoxelRegion region =
      gi::doubled_box_region(sg.virtual_objects.bounds_min, sg.virtual_objects.bounds_max, level.volume_cells, kMinRegionSide);
  scene_visibility_->set_region(region);
  object_visibility_->set_region(region);
  light_->set_region(region);
  delta_->set_region(region);
  object_light_->set_region(region);

  const light::Lighting& lighting = shared_.light_stage->lighting();
  reuse_.set_frame(info.level, info.camera_to_world, info.camera, sg.revision());
  for (size_t i = 0, n = 0; i < lighting.lights.size() && n < level.rsm_lamps; ++i)
    if (lighting.lights[i].real) {
      reuse_.add_lamp(lighting.lights[i]);
      ++n;
    }
  if (reuse_.close()) {
    skipped.push_back("dvct voxelisation and injection: reused (level, pose, depth, lamps and objects within tolerance of the frame that made them)");
    return ok_status();
  }
  reuse_.remember();
  object_light_valid_ = false;  // record_object_light injects it again where a cone reads it
  // Visibility: the real scene as the reconstruction sees it plus its proxy meshes; the objects.
  const VkExtent2D g = graph.extent(shared_.real_position);
  scene_visibility_->add_clear(graph);
  // The reconstruction's grid at about two points a voxel where the region is nearest the camera
  // (a G-buffer pixel spans depth / fx there; farther surfaces have larger pixels): at a coarse
  // level most pixels would splat into a voxel their neighbours already fill.
  const glm::vec3 camera(info.camera_to_world[3]);
  const float side_m = region.voxel_size * float(level.volume_cells);
  const float nearest = std::max(0.05f, glm::length(camera - (region.origin + glm::vec3(0.5f * side_m))) - 0.5f * side_m * std::sqrt(3.0f));
  const double fx = shared_.color_intrinsics.fx * double(g.width) / double(std::max(shared_.color_intrinsics.width, 1));
  const float pixel_m = nearest / float(std::max(fx, 1.0));
  const uint32_t grid_stride = std::clamp(uint32_t(0.5f * region.voxel_size / pixel_m), 1u, 8u);
  scene_visibility_->add_depth_surface(graph, "reconstruction", shared_.real_position, shared_.real_normal, g.width,
                                       g.height, grid_stride);
  auto ranges = [](const frame::MeshSet& set) {
    std::vector<gi::TriangleRange> out;
    for (const frame::DrawRange& r : set.draws) out.push_back({r.first_index, r.index_count, r.vertex_offset});
    return out;
  };
  if (!sg.real_proxies.empty())
    scene_visibility_->add_mesh(graph, "proxies", sg.real_proxies.vertices, sg.real_proxies.indices, ranges(sg.real_proxies));
  scene_visibility_->add_resolve(graph);
  // The objects' visibility depends on their meshes and poses alone (the region follows their
  // bounds): kept while they have not moved and the level's size is the same.
  if (object_source_.revision == sg.revision() && object_source_.cells == level.volume_cells && object_source_.valid) {
    skipped.push_back("dvct object visibility: reused (the objects have not moved since it was voxelised)");
  } else {
    object_visibility_->add_clear(graph);
    object_visibility_->add_mesh(graph, "objects", sg.virtual_objects.vertices, sg.virtual_objects.indices, ranges(sg.virtual_objects));
    object_visibility_->add_resolve(graph);
    object_source_ = {true, sg.revision(), level.volume_cells};
  }

  // Light: each real lamp's map pair (strongest first), R^rho into the light volume, the pair
  // into the delta volume.
  light_->add_clear(graph);
  delta_->add_clear(graph);
  const float side = region.voxel_size * float(level.volume_cells);
  const glm::vec3 centre = region.origin + glm::vec3(0.5f * side);
  const float radius = 0.5f * side * std::sqrt(3.0f);
  // The real grid at about two points a map texel across the G-buffer's larger side (as dlpv).
  const uint32_t stride = std::max(1u, uint32_t(std::ceil(double(std::max(g.width, g.height)) / (level.rsm_size / 2.0))));
  bool grid_added = false;
  uint32_t lamps = 0;
  for (size_t i = 0; i < lighting.lights.size() && lamps < level.rsm_lamps; ++i) {
    const LightDesc& lamp = lighting.lights[i];
    if (!lamp.real) continue;
    auto view = gi::rsm_view(lamp, centre, radius, level.rsm_size);
    if (!view) {
      skipped.push_back("dvct rsm (light " + std::to_string(i) + "): " + view.error().message);
      continue;
    }
    if (!grid_added) {
      rsm_->add_grid(graph, stride);
      grid_added = true;
    }
    const std::string id = std::to_string(i);
    const gi::RsmImages rho = rsm_->images(gi::RsmMap::WithVirtual, level.rsm_size);
    const gi::RsmImages mu = rsm_->images(gi::RsmMap::RealOnly, level.rsm_size);
    rsm_->add_pair(graph, id, *view, level.rsm_size);
    light_->add_inject(graph, id, rho, 1.0f);
    delta_->add_inject(graph, id, rho, 1.0f, &mu);
    ++lamps;
  }
  if (lamps == 0)
    skipped.push_back("dvct injection: no real light to inject (no lamp, environment region or estimate); the cones still shade");
  light_->add_resolve(graph);
  delta_->add_resolve(graph);
  return ok_status();
}

// Whether this frame shows a glossy surface: the objects' box (with a glossy virtual material) or
// a glossy real region's box not wholly outside the colour camera's frustum (tested plane by plane
// on its corners: conservative, a box beside a frustum corner may count as in view).
bool Dvct::glossy_in_view(const frame::FrameInfo& info) const {
  const glm::dmat4 to_camera = glm::inverse(info.camera_to_world);
  const Intrinsics& k = shared_.color_intrinsics;
  auto box_in_view = [&](const glm::vec3& lo, const glm::vec3& hi) {
    int outside[5] = {0, 0, 0, 0, 0};  // behind, left, right, above, below
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 w((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
      const glm::dvec3 p(to_camera * glm::dvec4(w, 1.0));  // OpenCV camera: x right, y down, z forward
      outside[0] += p.z < 1e-3;
      outside[1] += p.x < -p.z * k.cx / k.fx;
      outside[2] += p.x > p.z * (k.width - k.cx) / k.fx;
      outside[3] += p.y < -p.z * k.cy / k.fy;
      outside[4] += p.y > p.z * (k.height - k.cy) / k.fy;
    }
    return std::count(std::begin(outside), std::end(outside), 8) == 0;
  };
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  if (sg.has_glossy() && info.virtual_objects_present && box_in_view(sg.virtual_objects.bounds_min, sg.virtual_objects.bounds_max))
    return true;
  for (const RealMaterialRegion& r : glossy_regions_)
    if (box_in_view(r.min, r.max)) return true;
  return false;
}

// The objects' own light for the specular cone (DvctLevel::object_light), injected once per
// rebuild of the volumes (record_volumes clears object_light_valid_).
void Dvct::record_object_light(std::vector<std::string>& skipped) {
  if (object_light_valid_) {
    skipped.push_back("dvct object light: reused with the volumes");
    return;
  }
  gpu::FrameGraph& graph = *shared_.graph;
  object_light_->add_clear(graph);
  if (surfaces_layout_ != shared_.scene_gpu->layout_revision()) set_object_ranges();  // objects added or removed
  object_light_->add_inject_surfaces(graph, "objects", object_surfaces_);
  object_light_->add_resolve(graph);
  object_light_valid_ = true;
}

// The environment grid's pyramid into this slot's buffer for the specular cone; returns its
// (width, levels), (0, 0) without a grid this frame (the cone takes the ambient's irradiance).
glm::vec2 Dvct::write_environment() {
  const light::EnvSampler* grid = shared_.light_stage->environment_grid();
  if (!grid || grid->settings().grid_width != env_width_ || env_width_ < 4) return glm::vec2(0.0f);
  const int levels = grid->cone_pyramid(kEnvLevels, env_scratch_);
  gpu::FrameGraph& graph = *shared_.graph;
  std::copy(env_scratch_.begin(), env_scratch_.end(), static_cast<glm::vec4*>(graph.mapped(env_cells_, graph.slot())));
  return glm::vec2(float(env_width_), float(levels));
}

void Dvct::add_cone_pass(const DvctLevel& level, const shader::DvctParams& params, bool specular,
                         gpu::ImageHandle env_occlusion) {
  gpu::FrameGraph& graph = *shared_.graph;
  const Variant key{level.diffuse_cones, specular};
  const gpu::Pipeline* pipe = level.shadow_cones ? &*shade_.at(key) : &*indirect_.at(key);
  const frame::FrameResources& r = shared_;
  const VkSampler linear = shared_.context->samplers().linear_clamp;
  const gpu::ImageHandle light = light_->volume().image(0), delta = delta_->volume().image(0);
  const gpu::ImageHandle object_light = object_light_->volume().image(0);
  const gpu::ImageHandle scene = scene_visibility_->volume().image(0), object = object_visibility_->volume().image(0);
  const bool full = level.shadow_cones;
  const gpu::ImageHandle indirect = indirect_image_;
  const gpu::BufferHandle lights = lights_, materials = real_materials_, env = env_cells_;
  const uint32_t divisor = std::max(1u, level.trace_divisor);
  graph.add_shader_pass(
      full ? "dvct shade" : "dvct cones", gpu::PassKind::Compute, *pipe,
      [&, full, indirect, lights, materials, env, env_occlusion](gpu::ShaderPassBuilder& b) {
        if (full) {
          frame::bind_shading_gbuffers(b, r);
          b.bind("env_occlusion", env_occlusion);
        } else {
          frame::bind_gbuffer_reads(b, r);
          b.bind("indirect", indirect);
        }
        b.bind("LightUbo", lights);
        b.bind("RealMaterialUbo", materials);
        b.bind("EnvCells", env);
        b.bind_sampled("light_volume", light, linear);
        b.bind_sampled("delta_volume", delta, linear);
        b.bind_sampled("scene_visibility", scene, linear);
        b.bind_sampled("object_visibility", object, linear);
        b.bind_sampled("object_light", object_light, linear);
      },
      [pipe, params, lit = r.lit_rv, divisor](VkCommandBuffer cmd, gpu::PassContext& p) {
        const VkExtent2D e = p.extent(lit);
        const uint32_t w = (e.width + divisor - 1) / divisor, h = (e.height + divisor - 1) / divisor;
        gpu::push_and_dispatch(cmd, *pipe, &params, sizeof params, {(w + 7) / 8, (h + 7) / 8, 1});
      });
}

Status Dvct::record(const frame::FrameInfo& info, std::vector<std::string>& skipped) {
  direct_->begin_frame();
  auto level_or = level_for(info);
  if (!level_or) return level_or.error();
  const DvctLevel& level = **level_or;
  gpu::FrameGraph& graph = *shared_.graph;
  auto* set = static_cast<shader::LightSet*>(graph.mapped(lights_, graph.slot()));
  light::write_unshadowed_light_set(shared_.light_stage->lighting(), *set);
  *static_cast<shader::DvctRealMaterials*>(graph.mapped(real_materials_, graph.slot())) = real_material_table_;
  shader::DvctParams params{};
  const bool volumes = has_virtual_ && shared_.scene_gpu->any_visible();
  const bool specular = level.specular_cone && glossy_ && glossy_in_view(info);
  if (volumes) {
    MRGI_TRY(record_volumes(level, info, skipped));
    const gi::VoxelRegion& region = light_->region();
    params.volume = glm::vec4(region.origin, region.voxel_size);
    params.trace = glm::vec4(float(level.volume_cells), float(light_->volume().used_levels() - 1), kOcclusionFloor,
                             level.step_scale);
    params.cones = glm::vec4(level.shadow_aperture, kMinSpecularAperture,
                             region.voxel_size * float(level.volume_cells) * std::sqrt(3.0f), kSpecularRoughnessLimit);
    const glm::vec2 env = specular ? write_environment() : glm::vec2(0.0f);
    params.texture = glm::vec4(float(light_->volume().settings().resolution), env.x, env.y, 0.0f);
    params.mode = glm::ivec4(int(std::max(1u, level.trace_divisor)), 1, 0, 0);
  } else {
    reuse_.forget();
    skipped.push_back("dvct volumes and cones: no virtual object in the scene (nothing changes the real scene's light)");
    params.volume = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    params.trace = glm::vec4(2.0f, 0.0f, kOcclusionFloor, level.step_scale);
    params.texture = glm::vec4(2.0f, 0.0f, 0.0f, 0.0f);
    params.mode = glm::ivec4(int(std::max(1u, level.trace_divisor)), 0, 0, 0);
  }
  if (!level.specular_cone)
    skipped.push_back("dvct specular cone: level '" + std::string(level.name) + "' traces none");
  else if (!glossy_)
    skipped.push_back("dvct specular cone: no glossy material in the scene (virtual: metallic > 0.1 or roughness < 0.7; real: no such scene.json real_materials region)");
  else if (!specular)
    skipped.push_back("dvct specular cone: no glossy material in view (compiled out this frame)");
  if (specular && volumes && level.object_light) {
    record_object_light(skipped);
    params.mode.w = 1;
  }
  if (level.shadow_cones) {
    // The cones shadow the lamps; the ambient's occlusion by the objects is the block's.
    // The voxels' cones carry the lamps' bounce off the objects: the block's occlusion leaves it out.
    shading::EnvOcclusionLevel occlusion_level = shading::direct_light_levels()[size_t(level.baseline_level)].env_occlusion;
    occlusion_level.lights_bounce = occlusion_level.lights_bounce && !volumes;
    occlusion_level.real_bounce_loss_lights = occlusion_level.real_bounce_loss_lights && !volumes;
    const auto occlusion = direct_->record_env_occlusion(occlusion_level, skipped);
    params.mode.z = occlusion.divisor;
    add_cone_pass(level, params, specular, occlusion.image);
    return ok_status();
  }
  shading::DirectLightLevel direct = shading::direct_light_levels()[size_t(level.baseline_level)];
  if (!volumes) return direct_->record(info, direct, {}, skipped);
  direct.env_occlusion.lights_bounce = false;  // the cones carry it
  direct.env_occlusion.real_bounce_loss_lights = false;  // and the light the shadows keep from the ground
  add_cone_pass(level, params, specular, {});
  return direct_->record(info, direct, shading::ScreenIndirect{indirect_image_, int(std::max(1u, level.trace_divisor))},
                         skipped);
}

}  // namespace

Expected<std::unique_ptr<Technique>> create_dvct(const frame::FrameResources& shared, const TechniqueOptions& options) {
  auto levels = dvct_levels(options.knobs);
  if (!levels) return levels.error();
  auto t = std::make_unique<Dvct>(shared, std::move(*levels));
  MRGI_TRY(t->init());
  return std::unique_ptr<Technique>(std::move(t));
}

}  // namespace mrgi::technique
