// The technique interface (docs/DESIGN.md "Techniques"): one GI method from the papers per module,
// each in its own folder under technique/, registered by name in registry.cpp.
//
// A technique
//   - declares its quality ladder: ordered levels, best first, each a name and knobs with units;
//   - allocates everything it needs for its TOP level at start-up (create); lower levels use a
//     part of those resources (a smaller corner of a shadow map, a smaller internal resolution),
//     so changing level never allocates;
//   - records its passes into the frame graph for a given level (record), writing the two
//     solutions L_rv and L_r (linear radiance) that compose turns into the output;
//   - says which of its passes this frame needs: passes it leaves out are reported in
//     FrameStats::skipped as "pass: reason".
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frame/frame_resources.h"
#include "shading/direct_light.h"
#include "gpu/frame_graph.h"
#include "mrgi/expected.h"
#include "mrgi/light_estimate.h"
#include "mrgi/research.h"
#include "mrgi/runtime.h"

namespace mrgi::technique {

struct Knob {
  std::string name;   // e.g. "shadow_map_size"
  double value = 0.0;
  std::string unit;   // e.g. "texels per side", "fraction of output width and height"
  // What RuntimeSettings::knobs may set it to (technique/knobs.h): the ladder's span.
  double min = 0.0, max = 0.0;
  bool power_of_two = false;
};

struct QualityLevel {
  std::string name;
  std::vector<Knob> knobs;
  // Fraction of the output resolution the G-buffers and solutions use at this level, (0, 1].
  // Every technique has it: the runtime applies it as the frame graph's render scale.
  float internal_scale = 1.0f;
  // Largest projected geometric error (internal pixels) of the level of detail the virtual
  // G-buffer draws each mesh range at (scene_gpu.h frame::DrawRange::lods); 0 = full detail. Applied
  // by the runtime. Not free in accuracy: meshoptimizer 0.18 simplifies by position only, so
  // the coarser triangles interpolate the normals over larger areas (baseline's 160x120 golden
  // capture: virtual RDE 0.240 -> 0.249 at 0.1 px, 0.314 at 0.5 px); only fast levels use it.
  float mesh_error_px = 0.0f;
  // Compose's tile classifier (shaders/compose/tile_classify.comp) keeps the camera frame in the
  // 8 x 8 tiles where the composite can move no pixel by more than this many 8-bit levels, for
  // any camera value; applied by the runtime. 0.5: a pixel within one level of composing every
  // pixel. The fast levels take 1.5 (within two levels): under environment light the objects'
  // faint occlusion of the sky far from them lists most of the frame at 0.5, and compose is then
  // about a third of such a frame's CPU (perf/results/compose/tile-tolerance-fast-levels-2026-12-08.md).
  float compose_tolerance = 0.5f;
};

class Technique {
 public:
  virtual ~Technique() = default;
  virtual const std::string& name() const = 0;
  virtual const std::vector<QualityLevel>& levels() const = 0;
  // Records this frame's passes for `info.level`; appends "pass: reason" for each pass left out.
  virtual Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) = 0;
  // What the technique needs of the frame's other stages, declared once (runtime/frame_stages.h
  // reads it to decide which stages run and how).
  struct Needs {
    // The runtime's reconstruction (recon/: real positions, normals, albedo). A technique with
    // its own geometry stage that reads the camera frame itself where it needs it (ssrt, paper
    // Sec. 4) says no, and the runtime records neither recon pass.
    bool reconstruction = true;
    // The technique's output needs an estimate it derives from the frames themselves, read back
    // a few frames late so nothing stalls (ssrt's light): while it has none
    // (estimate_pending()), the runtime runs a frame twice (records and submits it, waits for
    // it, drops its output, calls frames_completed() and records it again), so the first visible
    // frame is not lit by a guess.
    bool estimate_from_frames = false;
  };
  virtual Needs needs() const { return {}; }
  // With Needs::estimate_from_frames: no estimate yet, the next frame is primed.
  virtual bool estimate_pending() const { return false; }
  // The real-world light this technique estimated from the camera images (Needs::
  // estimate_from_frames), the newest one; nullptr for a technique that estimates none.
  virtual const LightEstimate* light_estimate() const { return nullptr; }
  // Called before the virtual G-buffer is recorded, on frames that record(): a technique whose
  // real geometry the virtual objects' depth test should use records the passes that make it
  // here and returns it from occlusion_geometry() (nullopt, the default: recon's positions).
  virtual Status record_geometry(const frame::FrameInfo& /*info*/, std::vector<std::string>& /*skipped*/) {
    return ok_status();
  }
  virtual std::optional<frame::RealGeometry> occlusion_geometry() const { return std::nullopt; }
  // Every frame submitted so far has completed (the runtime waited for all of them): what they
  // wrote for the host may be read now.
  virtual void frames_completed() {}
  // After record(): the 8 x 8 output tiles outside which this frame's output is the camera
  // frame (L_rv == L_r and nothing virtual there), as an indirect-dispatch argument buffer
  // (VkDispatchIndirectCommand, x = tile count) and the tile indices (ty * ceil(w / 8) + tx),
  // both written by this frame's passes. The solutions are then defined only inside the tiles,
  // and compose copies the camera frame elsewhere (both buffers need TRANSFER_SRC usage: the
  // host reads the list back to lay the tiles over the camera frame). Null handles (the
  // default): compose every pixel from the solutions.
  // composed: this frame's passes also wrote the composite of those tiles into
  // frame::FrameResources::composed_output (compose_encoded, the runtime's formula),
  // so compose runs no pass of its own; only where those handles are valid, for solutions at
  // the output size.
  struct ComposeTiles {
    gpu::BufferHandle args, list;
    bool composed = false;
  };
  virtual ComposeTiles compose_tiles() const { return {}; }
  // After record(): what this frame's direct-light block applied (shading/direct_light.h), for a
  // stage that lights points of its own the same way (specular/: what mirrors and glass show);
  // nullopt: this frame's shading drew no shadow maps (the stage then lights its points
  // unshadowed).
  virtual std::optional<shading::DirectLightOutput> direct_light() const { return std::nullopt; }
};

// A technique's own start-up settings (the frame's resources come in frame::FrameResources).
struct TechniqueOptions {
  // RuntimeSettings::knobs: create() applies them to the technique's ladder (knobs.h).
  std::vector<KnobSetting> knobs;
  ResearchSettings research;  // RuntimeSettings::research (its defaults: the published methods)
};
using TechniqueFactory = Expected<std::unique_ptr<Technique>> (*)(const frame::FrameResources&,
                                                                   const TechniqueOptions&);
// The ladder with RuntimeSettings::knobs applied (BadUsage for a knob it refuses).
using LadderFn = Expected<std::vector<QualityLevel>> (*)(const std::vector<KnobSetting>& knobs);

struct TechniqueEntry {
  const char* name;
  LadderFn ladder;           // the quality ladder without creating anything
  TechniqueFactory create;   // allocates for the top level
};

// Every technique built into this library, in a fixed order.
const std::vector<TechniqueEntry>& registered_techniques();
// BadUsage naming the known techniques when `name` is not one of them.
Expected<const TechniqueEntry*> find_technique(const std::string& name);

}  // namespace mrgi::technique
