// Light propagation volumes, the shared block of dlpv (and of any technique that propagates VPL
// light through a grid): VPLs from reflective shadow maps summed into cells as 2-band SH of
// intensity (gi/lpv_inject.comp), then N propagation steps (gi/lpv_propagate.comp), accumulated.
// The math is shaders/shared/lpv_math.h (one copy, unit-tested on the CPU). A delta volume
// (DLPV, paper eq. 13) is the same volume injected with +1 from the map with the virtual object
// and -1 from the one without.
//
// Per frame: add_clear(), any number of add_inject() (lamps x maps x direct/indirect), then
// add_propagate(). Everything is allocated at create() for `resolution`; set_cells() picks the
// used size of a cheaper level.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "gi/volume.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"

namespace mrgi::gi {

struct LpvSettings {
  std::string name = "lpv";     // prefix of its images and passes
  uint32_t resolution = 32;     // cells per side allocated (the largest level), 2..128
  // Strength of the damping of negative flux where it is a step along the propagation
  // (lpv_negative_damping, paper Sec. 4.4); 0 turns it off (the ablation).
  float negative_damping = 1.0f;
  // Volumes of at most kLocalCells per side propagate every step in one workgroup
  // (gi/lpv_propagate_local.comp: shared memory and barriers instead of a dispatch a step, the
  // cost on a CPU device); true keeps them on the one-step-a-dispatch path (tests compare both).
  bool one_step_a_dispatch = false;
  // VPLs are injected this many cells along their surface normal (paper eq. 12: half a cell, so
  // a surface does not light itself and no VPL sits behind its own surface); 0: the ablation.
  float vpl_shift_cells = 0.5f;
};
inline constexpr uint32_t kLocalCells = 8;

// Where the volume is this frame: its min corner and cell size, metres.
struct LpvGrid {
  glm::vec3 origin{0.0f};
  float cell_size = 0.1f;
};

// A reflective shadow map as the injection reads it (gi/lpv_inject.comp's bindings).
struct RsmImages {
  gpu::ImageHandle position;  // RGBA32F: world xyz (m), w 1 a real surface, 2 a virtual one, 0 none
  gpu::ImageHandle normal;    // RGBA16F: world normal
  gpu::ImageHandle flux;      // RGBA32F: rgb reflected flux (W); a: incident W per unit light colour
  uint32_t width = 0, height = 0;  // the used size
};

// The lamp an RSM was made for.
struct LpvLight {
  glm::vec3 direction_or_position{0.0f, -1.0f, 0.0f};  // travel direction (directional) or position (m)
  bool positional = false;
  glm::vec3 colour{1.0f};  // the lamp's colour (direct injection scales incident W by it)
};

// Indirect: the map's VPLs (eq. 12). IndirectFromReal: the VPLs of its real surfaces only
// (position w 1, not 2): the bounce light the real scene sends, without a virtual object's light
// onto itself (DlpvAblation::no_virtual_self_bounce). Direct: the light arriving at the map's
// texels where `other` (the pair's other map) sees another surface, i.e. the light the virtual
// objects block (Sec. 4.3.2; lpv_inject.comp says where this differs from the paper).
enum class InjectKind : uint8_t { Indirect, Direct, IndirectFromReal };

class LightPropagationVolume {
 public:
  // BadUsage naming the field for settings out of range; Device when the device has no float
  // atomics on images (VK_EXT_shader_atomic_float's shaderImageFloat32AtomicAdd).
  static Expected<LightPropagationVolume> create(gpu::FrameGraph& graph, const LpvSettings& settings);

  // Cells per side used from now on: resolution / k for an integer k, at least 2.
  Status set_cells(gpu::FrameGraph& graph, uint32_t cells);
  uint32_t cells() const { return steps_[0]->cells(); }
  void set_grid(const LpvGrid& grid) { grid_ = grid; }
  const LpvGrid& grid() const { return grid_; }
  const LpvSettings& settings() const { return settings_; }
  void set_negative_damping(float strength) { settings_.negative_damping = strength; }

  void add_clear(gpu::FrameGraph& graph) const;
  // `sign` +1 or -1 (a delta volume's two maps). The pass is named "<name> inject <label>".
  // `other`: for Direct, the map whose surfaces count as unblocked; for Indirect, if given, the
  // pair's other map, injected in the same pass with -sign (eq. 13 in one pass, the delta pair):
  // only the texels where the two maps hold different surfaces, since the others cancel exactly
  // (R^rho is R^mu's copy outside the virtual objects, ReflectiveShadowMaps::add_pair).
  void add_inject(gpu::FrameGraph& graph, const std::string& label, const RsmImages& rsm, const LpvLight& light,
                  InjectKind kind, float sign, const RsmImages* other = nullptr) const;
  // The injected light as step 0, then `steps` propagation steps, all summed into accumulated():
  // one graph pass ("<name> propagate").
  void add_propagate(gpu::FrameGraph& graph, uint32_t steps) const;
  // The sum of every step, one RGBA32F image per channel (R, G, B): 2-band SH of intensity.
  gpu::ImageHandle accumulated(uint32_t channel) const { return sum_->image(channel); }

 private:
  LightPropagationVolume() = default;
  LpvSettings settings_;
  LpvGrid grid_;
  std::optional<VoxelVolume> steps_[2];  // ping-pong
  std::optional<VoxelVolume> sum_;
  gpu::BufferHandle cells_;              // injection sums, 12 floats a cell
  gpu::PipelineHandle inject_[4];  // by lpv_inject.comp's kMode
  gpu::PipelineHandle resolve_, propagate_;
  gpu::PipelineHandle propagate_local_;  // <= kLocalCells per side: every step in one workgroup
  struct Bindings {
    uint32_t cells = 0, resolve_step[3]{}, resolve_sum[3]{}, from[3]{}, to[3]{}, sum[3]{};
  } bindings_;
};

}  // namespace mrgi::gi
