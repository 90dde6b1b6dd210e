#include "shading/environment_occlusion.h"

#include <algorithm>
#include <cmath>

#include "frame/scene_gpu.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "shared/occlusion_math.h"

namespace mrgi::shading {

glm::vec3 lit_patch_radiance(const frame::OrientedPatch& patch, const glm::vec3& centre,
                             const std::vector<LightDesc>& lights) {
  glm::dvec3 e(0.0);
  for (const LightDesc& l : lights) {
    glm::dvec3 to_light = -glm::dvec3(l.direction);
    double scale = double(l.intensity);
    if (l.type != LightType::Directional) {
      const glm::dvec3 d = glm::dvec3(l.position) - glm::dvec3(centre);
      const double dist = std::max(glm::length(d), 1e-3);
      to_light = d / dist;
      scale /= dist * dist;
      if (l.type == LightType::Spot) {
        const float cos_inner = std::cos(glm::radians(l.inner_angle_deg));
        const float cos_outer = std::cos(glm::radians(l.outer_angle_deg));
        scale *= double(shader::spot_falloff(float(glm::dot(glm::dvec3(l.direction), -to_light)), cos_outer, cos_inner));
      }
    }
    const double facing = std::max(glm::dot(glm::dvec3(patch.normal), to_light), 0.0);
    if (std::isfinite(scale) && scale > 0.0) e += glm::dvec3(l.color) * (scale * facing);
  }
  return glm::vec3(glm::dvec3(patch.albedo) * e / M_PI);
}

struct EnvironmentOcclusion::Impl {
  frame::FrameResources frame_;
  gpu::PipelineHandle pipeline_;
  gpu::BufferHandle set_;          // shader::EnvOcclusionSet, one per frame slot
  gpu::ImageHandle image_, none_;  // the result (allocated at the internal size), the stand-in
  int divisor_ = 0;                // this frame's; 0: left out
  std::vector<glm::vec4> spheres_, albedo_;  // reserved at start-up
  std::vector<int> object_;                  // each sphere's object ordinal
  void write_lit_objects(shader::EnvOcclusionSet& set, const std::vector<LightDesc>& lights) const;
};

EnvironmentOcclusion::EnvironmentOcclusion(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
EnvironmentOcclusion::~EnvironmentOcclusion() = default;

Expected<std::unique_ptr<EnvironmentOcclusion>> EnvironmentOcclusion::create(const frame::FrameResources& frame) {
  auto m = std::make_unique<Impl>();
  m->frame_ = frame;
  gpu::FrameGraph& graph = *frame.graph;
  auto pipe = gpu::load_compute_pipeline(*frame.context, "shading/environment_occlusion.comp", {});
  if (!pipe) return pipe.error();
  m->pipeline_ = std::move(*pipe);
  auto set = graph.create_buffer({"env_occlusion_set", sizeof(shader::EnvOcclusionSet), gpu::MemoryUsage::Upload, true},
                                 VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!set) return set.error();
  m->set_ = *set;
  // At the internal size (the largest any divisor needs); a frame uses its top-left corner.
  gpu::ImageDesc d;
  d.name = "env_occlusion";
  d.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  auto image = graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!image) return image.error();
  m->image_ = *image;
  auto none = graph.create_zero_image("env_occlusion_none", VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!none) return none.error();
  m->none_ = *none;
  m->spheres_.reserve(size_t(frame.scene_gpu->object_count()) * frame::SceneGpu::kOccluderSpheres);
  m->albedo_.reserve(m->spheres_.capacity());
  m->object_.reserve(m->spheres_.capacity());
  return std::unique_ptr<EnvironmentOcclusion>(new EnvironmentOcclusion(std::move(m)));
}

// Each lit object's centre (its proxies' centres weighted by their volume), its oriented patches
// and their radiance under `lights` there.
void EnvironmentOcclusion::Impl::write_lit_objects(shader::EnvOcclusionSet& set, const std::vector<LightDesc>& lights) const {
  const int spheres = set.count.x;
  glm::vec4 centre[MRGI_MAX_LIT_OBJECTS] = {};
  for (int i = 0; i < spheres; ++i) {
    const int k = object_[size_t(i)];
    if (k >= MRGI_MAX_LIT_OBJECTS) continue;
    const float volume = spheres_[size_t(i)].w * spheres_[size_t(i)].w * spheres_[size_t(i)].w;
    centre[k] += glm::vec4(glm::vec3(spheres_[size_t(i)]) * volume, volume);
  }
  frame::OrientedPatch patches[frame::SceneGpu::kOrientedPatches];
  static_assert(frame::SceneGpu::kOrientedPatches == MRGI_LIT_PATCHES, "one patch count");
  for (int k = 0; k < MRGI_MAX_LIT_OBJECTS; ++k) {
    const int n = centre[k].w > 0.0f ? frame_.scene_gpu->oriented_patches(size_t(k), patches) : 0;
    const glm::vec3 c = n > 0 ? glm::vec3(centre[k]) / centre[k].w : glm::vec3(0.0f);
    // The bounding sphere of the object's proxies, grown by a quarter for the surface beyond
    // the inscribed spheres: a virtual point inside it takes none of the object's light.
    float reach = 0.0f;
    for (int i = 0; i < spheres && n > 0; ++i)
      if (object_[size_t(i)] == k) reach = std::max(reach, glm::distance(glm::vec3(spheres_[size_t(i)]), c) + spheres_[size_t(i)].w);
    set.lit_centre[k] = glm::vec4(c, 1.25f * reach);
    for (int j = 0; j < MRGI_LIT_PATCHES; ++j) {
      const size_t slot = size_t(k * MRGI_LIT_PATCHES + j);
      set.lit_normal[slot] = j < n ? glm::vec4(patches[j].normal, patches[j].area) : glm::vec4(0.0f);
      set.lit_radiance[slot] = j < n ? glm::vec4(lit_patch_radiance(patches[j], c, lights), 0.0f) : glm::vec4(0.0f);
    }
  }
}

void EnvironmentOcclusion::record(const EnvOcclusionLevel& level, const light::ShRgb& ambient_in,
                                  const std::vector<light::Lighting::AmbientRegion>& regions_in,
                                  const std::vector<LightDesc>& lights, bool occlude_ambient,
                                  std::vector<std::string>& skipped) {
  Impl& m = *impl_;
  m.divisor_ = 0;
  const frame::SceneGpu& sg = *m.frame_.scene_gpu;
  if (level.spheres_per_object <= 0) {
    skipped.push_back("env_occlusion: off at this level");
    return;
  }
  if (!sg.any_visible()) {
    skipped.push_back("env_occlusion: no virtual object visible");
    return;
  }
  static const std::vector<light::Lighting::AmbientRegion> kNoRegions;
  const light::ShRgb ambient = occlude_ambient ? ambient_in : light::ShRgb{};
  const auto& regions = occlude_ambient ? regions_in : kNoRegions;
  const bool bounce = level.lights_bounce && !lights.empty();
  // The ambient's mean radiance (band 0) is what any sphere can hide at most on average.
  if (!(std::max({ambient[0].x, ambient[0].y, ambient[0].z}) > 0.0) && !bounce) {
    // (With the ambient not to be occluded, the caller has said why already.)
    if (occlude_ambient) skipped.push_back("env_occlusion: no ambient light to occlude and no light bouncing");
    return;
  }
  m.spheres_.clear();
  // Each object's first spheres_per_object proxies, as many as fit: with many objects, the first
  // ones of every object before more of any (a round-robin over ranks).
  const int objects = std::max<int>(1, int(sg.object_count()));
  const int per_object = std::min(level.spheres_per_object, std::max(1, MRGI_MAX_OCCLUDER_SPHERES / objects));
  m.albedo_.clear();
  m.object_.clear();
  sg.occluder_spheres(per_object, m.spheres_, &m.albedo_, &m.object_);
  if (m.spheres_.empty()) {
    skipped.push_back("env_occlusion: the visible objects have no solid to stand in for");
    return;
  }
  m.divisor_ = std::clamp(level.divisor, 1, 8);
  auto* set = static_cast<shader::EnvOcclusionSet*>(m.frame_.graph->mapped(m.set_, m.frame_.graph->slot()));
  // The regions kept as cones leave the SH the caps are evaluated on.
  const int kept = std::clamp(std::min(level.regions, int(regions.size())), 0, MRGI_MAX_OCCLUSION_REGIONS);
  light::ShRgb rest = ambient;
  for (int k = 0; k < kept; ++k) {
    const light::Lighting::AmbientRegion& r = regions[size_t(k)];
    for (size_t i = 0; i < rest.size(); ++i) rest[i] -= r.sh[i];
    set->regions[k] = glm::vec4(glm::vec3(r.direction), float(1.0 - std::cos(r.half_angle_rad)));
    set->region_irradiance[k] = glm::vec4(glm::vec3(r.irradiance), float(r.half_angle_rad));
  }
  // Without an occluded ambient there is nothing beyond a sphere to hide: no march.
  set->count = glm::ivec4(int(std::min<size_t>(m.spheres_.size(), MRGI_MAX_OCCLUDER_SPHERES)), m.divisor_, kept,
                          occlude_ambient ? std::clamp(level.near_field_steps, 0, 64) : 0);
  set->near_field = glm::vec4(std::max(level.near_field_m, 0.0f), bounce ? 1.0f : 0.0f, 0.0f, 0.0f);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 4; ++k) {
      const size_t i = size_t(k * 4);
      set->radiance[c * 4 + k] =
          glm::vec4(float(rest[i][c]), float(rest[i + 1][c]), float(rest[i + 2][c]), float(rest[i + 3][c]));
    }
  for (size_t i = 0; i < size_t(set->count.x); ++i) {
    set->spheres[i] = m.spheres_[i];
    set->albedo[i] = glm::vec4(glm::vec3(m.albedo_[i]), bounce && m.object_[i] < MRGI_MAX_LIT_OBJECTS ? float(m.object_[i]) : -1.0f);
  }
  if (bounce) m.write_lit_objects(*set, lights);
  const frame::FrameResources& r = m.frame_;
  const int divisor = m.divisor_;
  r.graph->add_shader_pass(
      "env_occlusion", gpu::PassKind::Compute, *m.pipeline_,
      [&r, &m](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", r.frame_constants);
        b.bind("OcclusionUbo", m.set_);
        b.bind("real_position", r.real_position);
        b.bind("real_normal", r.real_normal);
        b.bind("virtual_position", r.virtual_position);
        b.bind("virtual_normal", r.virtual_normal);
        b.bind("color_words", r.color_upload);
        b.bind("env_occlusion", m.image_);
      },
      [&m, divisor](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(m.frame_.lit_rv);
        gpu::dispatch_2d(cmd, *m.pipeline_, nullptr, 0, (e.width + uint32_t(divisor) - 1) / uint32_t(divisor),
                         (e.height + uint32_t(divisor) - 1) / uint32_t(divisor));
      });
}

gpu::ImageHandle EnvironmentOcclusion::image() const { return impl_->divisor_ > 0 ? impl_->image_ : impl_->none_; }
int EnvironmentOcclusion::divisor() const { return impl_->divisor_; }

}  // namespace mrgi::shading
