// Virtual point lights from reflective shadow map pairs, a shared block of the VPL-based
// techniques (dir now): per real lamp, the DIR paper's two maps (Sec. 3.3, 3.7) are gi/rsm.h's
// pair (R^mu holds the real casters; R^rho's virtual texels are what a map of the virtual
// casters alone would show the lamp, the rest is R^mu), sampled into a buffer of VPL slots
// (common/vpl.glsl) by importance: a Halton value picks the real or the virtual map in
// proportion to the texels each covers, hierarchical warping (Clarberg et al. 2005, the GPU
// walk of gi/importance.h's pyramid) picks a texel in proportion to its reflected flux's
// luminance, and the VPL's flux is divided by the probability of that choice (the paper's
// intensity compensation: the VPLs' expected sum is the maps' reflected flux).
//
// Allocated once: `max_vpls` slots and one importance pyramid (RGBA32F mip chain) for maps up to
// `map_size` texels per side; a pair is sampled at its used size (a power of two).
#pragma once
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "gi/light_propagation.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gi {

struct VplSettings {
  std::string name = "vpl";  // prefix of the resources' and passes' names
  uint32_t max_vpls = 256;   // VPL slots allocated (the largest level's count), 1..4096
  uint32_t map_size = 512;   // largest map side sampled (texels), a power of two, 16..4096
  // The slots keep their contents between frames (gpu::BufferDesc::history): a frame that does
  // not sample reads what the last one left (dir reuses its VPLs while nothing moved).
  bool history = false;
  // VPLs on virtual texels whose material has a specular lobe (glTF roughness, metallic) get it
  // (common/vpl.glsl Vpl::lobe, shared/vpl_math.h vpl_glossy_split); off: every VPL diffuse,
  // reflecting its texel's whole flux. Fixed for the sampler's life (a scene's materials are).
  bool glossy = false;
};

// The lamp of a pair of maps as the VPLs need it: where its light comes from (gi/rsm.h
// RsmView::light: xyz position, w > 0; or xyz the direction it travels, w < 0) and its colour x
// intensity (the maps' flux alpha is per unit of it).
struct VplLamp {
  glm::vec4 light{0.0f, 0.0f, 0.0f, 1.0f};
  glm::vec3 colour{1.0f};
};

// Caustic VPLs (caustics-DIR paper Sec. 4.2.2): the lamp's photons (specular/caustics.h, two a
// photon-map texel: the reflected and the refracted one), so a VPL drawn on a mirror or glass
// texel moves to where one of its texel's photons landed (a Halton choice when both did, its
// flux then doubled), with that path's Fresnel and transmittance weight and the albedo there;
// a texel whose photons both left the scene gives no VPL.
struct VplCaustics {
  gpu::BufferHandle photons;   // shader::Photon[2 * size * size]
  glm::mat4 view_proj{1.0f};   // the photon map's view
  uint32_t size = 0;           // its side (texels)
};

class VplSampler {
 public:
  // BadUsage naming the field for settings out of range.
  static Expected<VplSampler> create(gpu::FrameGraph& graph, const VplSettings& settings);

  // A transfer pass emptying every slot (flags 0: lights nothing); "<name> clear".
  void add_clear(gpu::FrameGraph& graph) const;
  // Slots [first, first + count) from the pair `rho` / `mu` (gi/rsm.h images at their used size,
  // square, a power of two <= map_size) of a real lamp (`real_lamp`: both maps and the path
  // flags of Sec. 3.3; else R^rho's texels as one map, as the paper's virtual spot light).
  // Passes "<name> importance <id>", "<name> pyramid <id> <level>", "<name> sample <id>".
  // `caustics`: this lamp's photons (nullptr: VPLs stay on mirrors and glass as on any surface).
  Status add_sample(gpu::FrameGraph& graph, const std::string& id, const RsmImages& rho, const RsmImages& mu,
                    bool real_lamp, const VplLamp& lamp, uint32_t first, uint32_t count,
                    const VplCaustics* caustics = nullptr);

  // Slots [first, first + count) from `source` (shader::Vpl[count], the bounce light source's);
  // the other slots keep what they hold. Pass "<name> copy <id>".
  Status add_copy(gpu::FrameGraph& graph, const std::string& id, gpu::BufferHandle source, uint32_t first,
                  uint32_t count) const;

  gpu::BufferHandle buffer() const { return vpls_; }  // shader::Vpl[max_vpls]
  uint32_t max_vpls() const { return settings_.max_vpls; }

 private:
  VplSampler() = default;
  VplSettings settings_;
  uint32_t levels_ = 1;
  gpu::ImageHandle pyramid_;
  gpu::BufferHandle vpls_;
  gpu::BufferHandle no_photons_;  // bound when a pair has no caustics (never read)
  gpu::PipelineHandle importance_, downsample_, sample_, copy_;
};

}  // namespace mrgi::gi
