// The bounce light source of the DIR paper (Sec. 3.7 "a special primary light source that
// performs one light bounce", eq. 9-10), a shared block of the VPL-based techniques: new VPLs on
// the scene's surfaces lit by the previous frame's VPLs, seen through the previous frame's
// imperfect shadow maps (gi/ism.h), so every frame adds one bounce to the last and the light
// converges to multiple bounces over a few frames of a still scene. Candidate points are the
// ISMs' point clouds (the real G-buffer inside the influence sphere, the virtual meshes); the
// source VPL of a candidate is drawn by importance (its flux's luminance), and each slot keeps one
// of its candidates drawn in proportion to its reflected flux, the flux divided by that
// probability (shaders/gi/vpl_bounce.comp says why not the paper's strongest-survives).
//
// Order in a frame: add_bounce() before the frame's VPLs and ISMs are made (it reads the
// previous ones), VplSampler::add_copy() of buffer() into the bounce slots after the clear.
// Allocated once for `max_slots` slots.
#pragma once
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "gi/ism.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "frame/scene_gpu.h"

namespace mrgi::gi {

struct VplBounceSettings {
  std::string name = "vpl bounce";  // prefix of the resources' and passes' names
  uint32_t max_slots = 64;          // bounce VPL slots allocated (the largest level's), 1..1024
  // Glossy VPLs (gi/vpl.h VplSettings::glossy): the sources' lobes light the candidates, and a
  // candidate on a virtual surface with a lobe becomes a glossy VPL; off: every VPL diffuse.
  bool glossy = false;
};

// The real G-buffer the real candidates are read from (xyz world + depth, normal, albedo).
struct BounceGBuffer {
  gpu::ImageHandle position, normal, albedo;
};

// One frame's bounce.
struct BounceFrame {
  uint32_t slots = 0;                // bounce VPLs made (<= max_slots)
  uint32_t source_vpls = 0;          // the previous frame's VPL slots, 1..256 (its buffer's first)
  uint32_t source_ism_size = 0;      // texels per side of the previous frame's ISMs
  uint32_t source_tiles_per_row = 0; // tiles per atlas row of the previous frame's ISMs
  glm::vec3 centre{0.0f};            // influence sphere (world, m): real candidates inside it only
  float radius = 1.0f;
  float clamp_m = 0.01f;             // the VPLs' 1/d^2 clamp distance (m), as the shading's
  float bias_relative = 0.05f;       // ISM test bias, as the shading's
  float bias_m = 0.01f;
  glm::vec2 focal_px{0.0f};          // the G-buffer's focal lengths in its pixels
};

class VplBounce {
 public:
  static constexpr uint32_t kMaxSources = 256;  // MRGI_BOUNCE_MAX_SOURCES of vpl_bounce.comp
  // BadUsage naming the field for settings out of range.
  static Expected<VplBounce> create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                    const BounceGBuffer& gbuffer, const VplBounceSettings& settings);
  // Pass "<name>": reads `previous_vpls` (gi/vpl.h's buffer) and `previous_ism` (gi/ism.h's
  // distances) as the last frame left them, writes buffer()[0, frame.slots).
  Status add_bounce(gpu::FrameGraph& graph, gpu::BufferHandle previous_vpls, gpu::ImageHandle previous_ism,
                    const BounceFrame& frame) const;
  gpu::BufferHandle buffer() const { return bounce_; }  // shader::Vpl[max_slots]
  uint32_t max_slots() const { return settings_.max_slots; }

 private:
  VplBounce() = default;
  VplBounceSettings settings_;
  const frame::SceneGpu* scene_ = nullptr;
  BounceGBuffer gbuffer_;
  gpu::BufferHandle bounce_;
  gpu::PipelineHandle pipeline_;
};

}  // namespace mrgi::gi
