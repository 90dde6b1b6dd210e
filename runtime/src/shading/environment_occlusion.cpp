#include "shading/environment_occlusion.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "frame/scene_gpu.h"
#include "light/probeless.h"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "shared/occlusion_math.h"

namespace mrgi::shading {

namespace {

// Irradiance (W/m^2 per channel) light `l` gives a surface at `at` with unit `normal`, no
// shadowing (light::lamp_irradiance at normal incidence times the cosine); `to_light` the unit
// direction towards it.
glm::dvec3 light_irradiance(const LightDesc& l, const glm::dvec3& at, const glm::dvec3& normal, glm::dvec3& to_light) {
  const glm::dvec3 normal_incidence = light::lamp_irradiance(l, at, to_light);  // sets to_light first
  const glm::dvec3 e = normal_incidence * std::max(glm::dot(normal, to_light), 0.0);
  return std::isfinite(e.x + e.y + e.z) ? glm::max(e, glm::dvec3(0.0)) : glm::dvec3(0.0);
}

// Directions spread evenly over the sphere (a Fibonacci lattice, +y the axis) with their SH
// basis: the quadrature of real_bounce_flux.
constexpr size_t kFluxDirections = 256;
struct FluxDirections {
  std::array<glm::dvec3, kFluxDirections> w;
  std::array<std::array<double, 16>, kFluxDirections> basis;
};
const FluxDirections& flux_directions() {
  static const FluxDirections d = [] {
    FluxDirections out{};
    for (size_t i = 0; i < kFluxDirections; ++i) {
      out.w[i] = light::fibonacci_direction(int(i), int(kFluxDirections));
      const shader::SH16 b = shader::sh_basis16(glm::vec3(out.w[i]));
      for (int k = 0; k < 16; ++k) out.basis[i][size_t(k)] = double(shader::sh_get(b, k));
    }
    return out;
  }();
  return d;
}

}  // namespace

glm::vec3 lit_patch_radiance(const frame::OrientedPatch& patch, const glm::vec3& centre,
                             const std::vector<LightDesc>& lights) {
  glm::dvec3 e(0.0), to_light;
  for (const LightDesc& l : lights) e += light_irradiance(l, glm::dvec3(centre), glm::dvec3(patch.normal), to_light);
  return glm::vec3(glm::dvec3(patch.albedo) * e / M_PI);
}

glm::vec3 real_bounce_flux(const frame::OrientedPatch* patches, int count, const light::ShRgb& ambient,
                           const std::vector<LightDesc>& lights, const glm::vec3& centre, const glm::vec3& base) {
  const FluxDirections& dirs = flux_directions();
  const double d_omega = 4.0 * M_PI / double(kFluxDirections);
  std::array<glm::dvec3, kFluxDirections> radiance;
  glm::dvec3 below(0.0), e_up(0.0), to_light;
  size_t below_count = 0;
  for (size_t i = 0; i < kFluxDirections; ++i) {
    glm::dvec3 l(0.0);
    for (size_t k = 0; k < 16; ++k) l += ambient[k] * dirs.basis[i][k];
    radiance[i] = glm::max(l, glm::dvec3(0.0));  // SH ringing is no light
    if (dirs.w[i].y < 0.0) {
      below += radiance[i];
      ++below_count;
    } else {
      e_up += radiance[i] * (dirs.w[i].y * d_omega);
    }
  }
  for (const LightDesc& l : lights) e_up += light_irradiance(l, glm::dvec3(base), glm::dvec3(0.0, 1.0, 0.0), to_light);
  // What the object takes from the light travelling down (which would have reached the ground
  // and the walls round it), less the part of its own reflection that goes down.
  glm::dvec3 intercepted(0.0), reflected(0.0);
  for (int j = 0; j < count; ++j) {
    const glm::dvec3 n(patches[j].normal);
    const double area = double(patches[j].area);
    if (!(area > 0.0)) continue;
    glm::dvec3 e_all(0.0), e_down(0.0);
    for (size_t i = 0; i < kFluxDirections; ++i) {
      const double c = glm::dot(n, dirs.w[i]);
      if (c <= 0.0) continue;
      const glm::dvec3 e = radiance[i] * (c * d_omega);
      e_all += e;
      if (dirs.w[i].y > 0.0) e_down += e;
    }
    for (const LightDesc& l : lights) {
      const glm::dvec3 e = light_irradiance(l, glm::dvec3(centre), n, to_light);
      e_all += e;
      if (to_light.y > 0.0) e_down += e;
    }
    intercepted += area * e_down;
    reflected += area * glm::dvec3(patches[j].albedo) * e_all * (0.5 * (1.0 - n.y));
  }
  // The surroundings' albedo: what the ground sends up (the ambient's mean radiance from below)
  // over the irradiance reaching it, pi L / E; at most 0.9.
  below /= double(std::max<size_t>(below_count, 1));
  glm::dvec3 albedo(0.0);
  for (int c = 0; c < 3; ++c) albedo[c] = e_up[c] > 1e-9 ? std::clamp(M_PI * below[c] / e_up[c], 0.0, 0.9) : 0.0;
  const glm::dvec3 flux = albedo * (intercepted - reflected);
  return std::isfinite(flux.x + flux.y + flux.z) ? glm::vec3(flux) : glm::vec3(0.0f);
}

struct EnvironmentOcclusion::Impl {
  frame::FrameResources frame_;
  // The general shader, and the one for spheres of object 0 alone (kOneObject: the per-object
  // values once a texel, not once a sphere).
  gpu::PipelineHandle pipeline_, one_object_pipeline_;
  gpu::BufferHandle set_;          // shader::EnvOcclusionSet, one per frame slot
  gpu::ImageHandle image_, none_;  // the result (allocated at the internal size), the stand-in
  int divisor_ = 0;                // this frame's; 0: left out
  std::vector<glm::vec4> spheres_, albedo_;  // reserved at start-up
  std::vector<int> object_;                  // each sphere's object ordinal
  void write_objects(shader::EnvOcclusionSet& set, const std::vector<LightDesc>& lights, const light::ShRgb& ambient,
                     bool bounce, bool loss, bool loss_lights) const;
};

EnvironmentOcclusion::EnvironmentOcclusion(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
EnvironmentOcclusion::~EnvironmentOcclusion() = default;

Expected<std::unique_ptr<EnvironmentOcclusion>> EnvironmentOcclusion::create(const frame::FrameResources& frame) {
  auto m = std::make_unique<Impl>();
  m->frame_ = frame;
  gpu::FrameGraph& graph = *frame.graph;
  auto spv = gpu::shader_spirv("shading/environment_occlusion.comp");
  if (!spv) return spv.error();
  for (uint32_t one : {0u, 1u}) {
    // Bindings and push constants from the shader (the pass binds by name).
    gpu::ComputePipelineDesc d{one ? "env_occlusion_one_object" : "env_occlusion", *spv, {}, 0, {one}};
    auto pipe = gpu::create_compute_pipeline(*frame.context, d);
    if (!pipe) return pipe.error();
    (one ? m->one_object_pipeline_ : m->pipeline_) = gpu::PipelineHandle(*frame.context, std::move(*pipe));
  }
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

// Each object's centre (its proxies' centres weighted by their volume), bounding radius, the
// disc area of its proxies (far_field_scale) and its oriented patches; with `bounce`, the
// patches' radiance under `lights`; with `loss`, the flux its surroundings reflect less
// (real_bounce_flux, of the lights too where `loss_lights`) and where from.
void EnvironmentOcclusion::Impl::write_objects(shader::EnvOcclusionSet& set, const std::vector<LightDesc>& lights,
                                               const light::ShRgb& ambient, bool bounce, bool loss,
                                               bool loss_lights) const {
  const int spheres = set.count.x;
  glm::vec4 centre[MRGI_MAX_OCCLUSION_OBJECTS] = {};
  float discs[MRGI_MAX_OCCLUSION_OBJECTS] = {}, lowest[MRGI_MAX_OCCLUSION_OBJECTS] = {};
  int objects = 0;
  for (int i = 0; i < spheres; ++i) {
    const int k = object_[size_t(i)];
    if (k >= MRGI_MAX_OCCLUSION_OBJECTS) continue;
    const glm::vec4 s = spheres_[size_t(i)];
    const float volume = s.w * s.w * s.w;
    lowest[k] = centre[k].w > 0.0f ? std::min(lowest[k], s.y - s.w) : s.y - s.w;
    centre[k] += glm::vec4(glm::vec3(s) * volume, volume);
    discs[k] += float(M_PI) * s.w * s.w;
    objects = std::max(objects, k + 1);
  }
  set.near_field.z = float(objects);
  frame::OrientedPatch patches[frame::SceneGpu::kOrientedPatches];
  static_assert(frame::SceneGpu::kOrientedPatches == MRGI_OBJECT_PATCHES, "one patch count");
  for (int k = 0; k < MRGI_MAX_OCCLUSION_OBJECTS; ++k) {
    const int n = centre[k].w > 0.0f ? frame_.scene_gpu->oriented_patches(size_t(k), patches) : 0;
    const glm::vec3 c = centre[k].w > 0.0f ? glm::vec3(centre[k]) / centre[k].w : glm::vec3(0.0f);
    // The bounding sphere of the object's proxies; grown by a quarter for the surface beyond
    // the inscribed spheres, a virtual point inside it takes none of the object's light.
    float reach = 0.0f;
    for (int i = 0; i < spheres; ++i)
      if (object_[size_t(i)] == k) reach = std::max(reach, glm::distance(glm::vec3(spheres_[size_t(i)]), c) + spheres_[size_t(i)].w);
    set.object_centre[k] = glm::vec4(c, 1.25f * reach);
    set.object_far[k] = glm::vec4(n > 0 ? discs[k] : 0.0f, reach, 0.0f, 0.0f);
    for (int j = 0; j < MRGI_OBJECT_PATCHES; ++j) {
      const size_t slot = size_t(k * MRGI_OBJECT_PATCHES + j);
      set.object_patch[slot] = j < n ? glm::vec4(patches[j].normal, patches[j].facing_area) : glm::vec4(0.0f);
      set.patch_radiance[slot] =
          bounce && j < n ? glm::vec4(lit_patch_radiance(patches[j], c, lights), 0.0f) : glm::vec4(0.0f);
    }
    const glm::vec3 base(c.x, lowest[k], c.z);
    set.object_base[k] = glm::vec4(base, 0.0f);
    static const std::vector<LightDesc> kNoLights;
    set.object_loss[k] = loss && n > 0 ? glm::vec4(real_bounce_flux(patches, n, ambient, loss_lights ? lights : kNoLights, c, base), reach)
                                       : glm::vec4(0.0f);
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
  const int objects = std::max<int>(1, int(sg.present_count()));  // (not the room's empty slots)
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
  const bool loss = level.real_bounce_loss;
  set->near_field = glm::vec4(std::max(level.near_field_m, 0.0f), bounce ? 1.0f : 0.0f, 0.0f, loss ? 1.0f : 0.0f);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 4; ++k) {
      const size_t i = size_t(k * 4);
      set->radiance[c * 4 + k] =
          glm::vec4(float(rest[i][c]), float(rest[i + 1][c]), float(rest[i + 2][c]), float(rest[i + 3][c]));
    }
  for (size_t i = 0; i < size_t(set->count.x); ++i) {
    set->spheres[i] = m.spheres_[i];
    set->albedo[i] = glm::vec4(glm::vec3(m.albedo_[i]), m.object_[i] < MRGI_MAX_OCCLUSION_OBJECTS ? float(m.object_[i]) : -1.0f);
  }
  m.write_objects(*set, lights, ambient, bounce, loss, level.real_bounce_loss_lights);
  const frame::FrameResources& r = m.frame_;
  const int divisor = m.divisor_;
  // Every sphere of object 0 or of none of the lit objects (albedo[i].w -1).
  const bool one_object = std::all_of(m.object_.begin(), m.object_.end(),
                                      [](int k) { return k == 0 || k >= MRGI_MAX_OCCLUSION_OBJECTS; });
  const gpu::Pipeline* pipe = one_object ? &*m.one_object_pipeline_ : &*m.pipeline_;
  r.graph->add_shader_pass(
      "env_occlusion", gpu::PassKind::Compute, *pipe,
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
      [&m, divisor, pipe](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(m.frame_.lit_rv);
        gpu::dispatch_2d(cmd, *pipe, nullptr, 0, (e.width + uint32_t(divisor) - 1) / uint32_t(divisor),
                         (e.height + uint32_t(divisor) - 1) / uint32_t(divisor));
      });
}

gpu::ImageHandle EnvironmentOcclusion::image() const { return impl_->divisor_ > 0 ? impl_->image_ : impl_->none_; }
int EnvironmentOcclusion::divisor() const { return impl_->divisor_; }

}  // namespace mrgi::shading
