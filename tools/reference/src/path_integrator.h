// Internals of the reference path tracer: the Embree scenes and the per-pixel integrator.
#pragma once
#include <embree3/rtcore.h>

#include <vector>

#include "bsdf.h"
#include "environment_sampler.h"
#include "mrgi/reference/path_tracer.h"
#include "sampling.h"

namespace mrgi::reference {

// Emissive triangles of one part of the scene (real or virtual), sampled uniformly by area.
struct EmitterSet {
  struct Tri {
    uint32_t mesh, prim;
  };
  std::vector<Tri> triangles;
  std::vector<float> cdf;  // normalised cumulative area
  float total_area = 0.0f;
  bool empty() const { return triangles.empty(); }
};

struct PathTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene real_scene = nullptr;     // geomID = index into real_meshes
  RTCScene virtual_scene = nullptr;  // geomID = index into virtual_meshes
  std::vector<RefMesh> real_meshes, virtual_meshes;
  std::vector<RefMaterial> materials;
  std::vector<ImageRGBF> textures;
  std::vector<RefLight> lights;
  bool has_virtual_lights = false;
  EnvironmentSampler environment;
  EmitterSet real_emitters, virtual_emitters;
};

struct Hit {
  bool found = false;
  bool is_virtual = false;
  uint32_t mesh = 0, prim = 0;
  float t = 0.0f, u = 0.0f, v = 0.0f;
};

struct SurfacePoint {
  glm::vec3 p{0.0f};
  glm::vec3 ng{0.0f, 0.0f, 1.0f};  // unit geometric normal, front side (counter-clockwise)
  glm::vec3 ns{0.0f, 0.0f, 1.0f};  // unit shading normal, same hemisphere as ng
  glm::vec2 uv{0.0f};
  const RefMaterial* material = nullptr;
};

class Integrator {
 public:
  Integrator(const PathTracer::Impl& scene, const RefCamera& camera, const RenderSettings& settings);
  // Renders pixel (x, y) into `out` (all spp samples); returns the number of dropped samples.
  size_t render_pixel(int x, int y, RenderOutput& out) const;
  // Light tracing of the paths the pixel estimator cannot sample (path_tracer.h): photons
  // [first, first + count) of `count_total` from delta lamp `light` towards the scene's delta
  // materials, followed through the specular vertices right after the lamp and connected to the
  // pinhole camera at every non-delta vertex after them; their radiance is added to `accum`
  // (w x h x 3, the pixels' mean radiance). `combined`: the real + virtual scene, else the real one.
  size_t trace_light_paths(size_t light, uint64_t first, uint64_t count, uint64_t count_total, bool combined,
                           std::vector<double>& accum) const;

 private:
  bool camera_ray(double px, double py, glm::vec3* origin, glm::vec3* dir, glm::vec3* dir_cam) const;
  Hit intersect(const glm::vec3& o, const glm::vec3& d, float tmax, bool combined) const;
  // True when the segment is blocked; in the combined scene sets *touched when only a virtual
  // object blocks it.
  bool occluded(const glm::vec3& o, const glm::vec3& d, float tmax, bool combined, bool* touched) const;
  SurfacePoint surface(const Hit& hit, const glm::vec3& o, const glm::vec3& d) const;
  ShadingPoint shading(const SurfacePoint& s) const;
  glm::vec3 direct_light(const SurfacePoint& s, const ShadingPoint& sp, const Frame3& frame,
                         const glm::vec3& wo_local, const glm::vec3& n_facing, const SampleRng& rng,
                         int bounce, bool combined, bool* touched) const;
  float emitter_pdf(const EmitterSet& set, float dist, float cos_light) const;
  glm::vec3 trace(glm::vec3 o, glm::vec3 d, const SampleRng& rng, bool combined, bool* touched) const;

  const PathTracer::Impl& scene_;
  const RefCamera& camera_;
  const RenderSettings& settings_;
  glm::mat3 cam_rot_;
  glm::vec3 cam_pos_;
  uint64_t frame_key_;
};

}  // namespace mrgi::reference
