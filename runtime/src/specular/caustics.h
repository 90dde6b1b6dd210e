// Caustics of spot lamps through the virtual mirrors and glass (caustics-DIR paper Sec. 4.2 and
// 5.2; Wyman and Davis 2006): per lamp whose cone holds a reflective or refractive object in
// view,
//   specular photon surfaces <l>     the objects' front faces from the lamp (PGBuf: position,
//                                    normal, material)
//   specular photon back faces <l>   the refractive objects' back faces from the lamp
//   specular photons <l>             a reflected and a twice refracted photon per texel, traced to
//                                    the impostors (photons.comp)
//   specular caustic splat <l>       the photons as quads into the camera's caustic buffer
//                                    (irradiance; caustic_splat.vert/.frag)
// The specular stage then adds the buffer to the diffuse pixels' L_rv (caustic_apply.comp) and
// to the surfaces its mirrors and glass show (trace.comp). Point and directional lamps make no
// caustics (the paper's spot lamps only: a point lamp would need a cube of photon maps).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "mrgi/scene.h"
#include "technique/technique.h"

namespace mrgi::specular {

class Caustics {
 public:
  // Lamps with caustic maps in one frame (the strongest spot lamps whose cone holds an object).
  static constexpr int kMaxLamps = 2;
  static Expected<Caustics> create(const technique::SharedResources& shared, uint32_t max_map_size,
                                   const gpu::Pipeline& back_faces);
  // What the photon pass reads of the specular stage: its constants (impostor sets, search
  // steps) and the impostor atlas.
  struct Impostors {
    gpu::BufferHandle constants;
    gpu::ImageHandle position, normal, albedo;
  };
  // Records the passes above for the lamps of `lamps` (the light stage's lights) that are spot
  // lamps whose cone meets the sphere (centre, radius) around `objects` (specular objects in
  // view), with maps of `map_size` texels. Returns whether a caustic buffer was written this
  // frame (false: no such lamp; `skipped` says why).
  bool record(gpu::FrameGraph& graph, const Impostors& impostors, const std::vector<LightDesc>& lamps,
              const std::vector<size_t>& objects, const glm::vec3& centre, float radius, uint32_t map_size,
              std::vector<std::string>& skipped);
  // The caustic buffer (RGBA16F, internal resolution): rgb irradiance (W/m^2) on the surface
  // each pixel shows, a the number of photons.
  gpu::ImageHandle buffer() const { return caustics_; }
  // This frame's photons per lamp (after record()).
  const technique::CausticPhotons& photons() const { return recorded_; }

 private:
  Caustics() = default;
  technique::SharedResources shared_;
  uint32_t max_map_ = 0;
  const gpu::Pipeline* back_faces_ = nullptr;
  gpu::ImageHandle position_, normal_, back_position_, back_normal_, depth_, caustics_;
  gpu::BufferHandle photons_[kMaxLamps], photon_list_, photon_draw_;
  technique::CausticPhotons recorded_;  // this frame's lamps
  gpu::PipelineHandle surface_pipeline_, photon_pipeline_, splat_pipeline_;
};

}  // namespace mrgi::specular
