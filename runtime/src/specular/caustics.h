// Caustics of spot lamps through the virtual mirrors and glass (caustics-DIR paper Sec. 4.2 and
// 5.2; Wyman and Davis 2006): per lamp whose cone holds a reflective or refractive object in
// view,
//   specular photon surfaces <l>     the objects' front faces from the lamp (PGBuf: position,
//                                    normal, material)
//   specular photon back faces <l>   the refractive objects' back faces from the lamp
//   specular photons <l>             a reflected and a twice refracted photon per texel, traced to
//                                    the impostors (photons.comp)
//   specular photon footprints <l>   each landed photon's spacing from its neighbours
//                                    (photon_footprint.comp: the splat's square size)
//   specular caustic receivers <l>   at levels with receiver maps: the photons as points into
//                                    the lamp's octahedral receiver map (caustic_receiver.vert/
//                                    .frag), which the technique's direct shading reads
// and, after the technique, unless its shading added the receiver maps (splat()):
//   specular caustic splat <l>       the photons as points into the camera's caustic buffer
//                                    (irradiance) and, times albedo / pi, into the diffuse
//                                    pixels' L_rv (caustic_splat.vert/.frag)
// The specular stage's trace reads the buffer for the surfaces under its mirrors and glass. Point and directional lamps make no
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
#include "specular/caustic_receiver.glsl"
#include "frame/frame_resources.h"

namespace mrgi::specular {

class Caustics {
 public:
  // Lamps with caustic maps in one frame (the strongest spot lamps whose cone holds an object).
  static constexpr int kMaxLamps = 2;
  static Expected<Caustics> create(const frame::FrameResources& shared, uint32_t max_map_size,
                                   uint32_t max_receiver_map, const gpu::Pipeline& back_faces);
  // What the photon pass reads of the specular stage: its constants (impostor sets, search
  // steps) and the impostor atlas.
  struct Impostors {
    gpu::BufferHandle constants;
    gpu::ImageHandle position, normal, albedo;
  };
  // How often the photons are traced. They are world-space (where each landed, its flux), so
  // while the lamps, the objects and the map size stay as they were, a frame may splat the
  // photons of an earlier one: only the splat is the camera's.
  struct Refresh {
    int period = 1;       // frames between traces of unchanged photons (1: every frame)
    bool busy = false;    // this frame already redraws impostors: a due trace waits a frame
    uint64_t revision = 0;  // the scene's (frame::SceneGpu::revision): a change traces at once
    int glass_reflection_stride = 1;  // the level's (photons.comp): a change traces at once
    uint32_t receiver_map = 0;  // the level's receiver map side (0: none): a change traces at once
  };
  // Records the photon passes for the lamps of `lamps` (the light stage's lights) that are spot
  // lamps whose cone meets the sphere (centre, radius) around `objects` (specular objects in
  // view), with maps of `map_size` texels. Returns whether this frame has caustics (false: no
  // such lamp; `skipped` says why); then splat() must follow.
  bool trace(gpu::FrameGraph& graph, const Impostors& impostors, const std::vector<LightDesc>& lamps,
              const std::vector<size_t>& objects, const glm::vec3& centre, float radius, uint32_t map_size,
              const Refresh& refresh, std::vector<std::string>& skipped);
  // After the technique's record() (it writes lit_rv): the splat of trace()'s photons, into the
  // caustic buffer and the runtime's lit_rv.
  void splat(gpu::FrameGraph& graph);
  // The caustic buffer (RGBA16F, internal resolution): rgb irradiance (W/m^2) on the surface
  // each pixel shows, a the number of photons.
  gpu::ImageHandle buffer() const { return caustics_; }
  // This frame's photons per lamp and receiver maps (after trace()).
  const frame::CausticPhotons& photons() const { return recorded_; }

 private:
  Caustics() = default;
  frame::FrameResources shared_;
  uint32_t max_map_ = 0;
  const gpu::Pipeline* back_faces_ = nullptr;
  gpu::ImageHandle position_, normal_, back_position_, back_normal_, depth_, caustics_;
  uint32_t max_receiver_ = 0;
  gpu::ImageHandle receivers_;        // the receiver maps' atlas (history: drawn when traced)
  gpu::BufferHandle receiver_lamps_;  // CausticReceivers, written every frame
  // Per lamp slot, history buffers: a frame that does not trace splats the last traced ones.
  gpu::BufferHandle photons_[kMaxLamps], photon_list_[kMaxLamps], photon_draw_[kMaxLamps];
  frame::CausticPhotons recorded_;  // this frame's lamps
  std::vector<glm::vec4> splat_push_;   // caustic_splat.vert's push block per lamp
  // create()'s steps, in its order.
  Status create_photon_maps();
  Status create_caustic_buffers();
  Status create_photon_buffers();
  Status create_photon_pipelines();
  Status create_splat_pipelines();
  // trace()'s steps.
  bool choose_lamps(const std::vector<LightDesc>& lamps, const glm::vec3& centre, float radius,
                    std::vector<std::string>& skipped);
  bool photons_due(uint32_t size, uint32_t receiver, const std::vector<size_t>& objects, const glm::vec3& centre,
                   float radius, const Refresh& refresh, std::vector<std::string>& skipped);
  void add_photon_passes(gpu::FrameGraph& graph, const Impostors& imp, size_t li, const LightDesc& lamp,
                         const glm::mat4& view_proj, const glm::vec3& axis, float half, uint32_t size,
                         const std::vector<size_t>& front, const std::vector<size_t>& back);
  // The photons of lamp slot li into its part of the receiver atlas (trace frames).
  void add_receiver_splat(gpu::FrameGraph& graph, size_t li, const shader::CausticReceiverLamp& lamp,
                          float largest_point);
  // What the photons in the buffers were traced for: the chosen lamps' parameters, the objects,
  // the map size and the scene revision, and when.
  std::vector<double> traced_key_;
  int64_t traced_frame_ = 0, frame_ = 0;
  // Scratch kept between frames (no allocation a frame once they have grown).
  std::vector<double> key_;
  std::vector<const LightDesc*> chosen_;
  gpu::PipelineHandle surface_pipeline_, photon_pipeline_, footprint_pipeline_, splat_pipeline_, receiver_pipeline_,
      receiver_mip_pipeline_;
};

}  // namespace mrgi::specular
