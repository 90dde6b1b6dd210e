// The technique interface (DESIGN.md "Techniques"): one GI method from the papers per module,
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

#include "gpu/frame_graph.h"
#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/light_estimate.h"
#include "mrgi/runtime.h"
#include "mrgi/scene.h"

namespace mrgi::gpu {
class Context;
}
namespace mrgi::light {
class LightStage;
}

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
  // G-buffer draws each mesh range at (scene_gpu.h DrawRange::lods); 0 = full detail. Applied
  // by the runtime. Not free in accuracy: meshoptimizer 0.18 simplifies by position only, so
  // the coarser triangles interpolate the normals over larger areas (baseline's 160x120 golden
  // capture: virtual RDE 0.240 -> 0.249 at 0.1 px, 0.314 at 0.5 px); only fast levels use it.
  float mesh_error_px = 0.0f;
};

// The shared start-up inputs of a technique (owned by the runtime, alive as long as it).
class SceneGpu;
struct SharedResources {
  gpu::Context* context = nullptr;
  DlpvAblation dlpv_ablation;  // RuntimeSettings::dlpv_ablation
  DirAblation dir_ablation;    // RuntimeSettings::dir_ablation
  // RuntimeSettings::knobs: the technique's create() applies them to its ladder (knobs.h); a
  // technique that makes another for a part of its frame (dir's baseline) hands on none.
  std::vector<KnobSetting> knobs;
  gpu::FrameGraph* graph = nullptr;
  const SceneDesc* scene = nullptr;
  const SceneGpu* scene_gpu = nullptr;     // uploaded virtual meshes and real proxies
  // The light stage (light/light_stage.h): its lighting() is this frame's light when record()
  // runs. A technique that sums its own probeless system hands it in (submit_system).
  light::LightStage* light_stage = nullptr;
  // Per frame, written by the runtime: FrameConstants (shaders/common/frame_constants.glsl).
  gpu::BufferHandle frame_constants;
  // Real G-buffer (recon/): positions (xyz world, w depth; 0 invalid), normals, albedo.
  gpu::ImageHandle real_position, real_normal, real_albedo;
  // Virtual G-buffer (recon/virtual_gbuffer): xyz world + coverage, normal + roughness,
  // base colour + metallic, emitted radiance (a technique adds it to L_rv where it shades a
  // virtual pixel; invalid when no material emits, FrameConstants::flags.y 0).
  gpu::ImageHandle virtual_position, virtual_normal, virtual_albedo, virtual_emission;
  // The solutions the technique writes (RGBA16F, internal resolution, linear radiance).
  gpu::ImageHandle lit_rv, lit_r;
  // This frame's raw inputs as uploaded by recon/ (per-slot buffers): colour sRGB8 packed as
  // 3 bytes per pixel (colour intrinsics' size), depth u16 (depth intrinsics' size, depth_scale
  // units per metre, 0 = no measurement), and the cameras they come from.
  gpu::BufferHandle color_upload, depth_upload;
  Intrinsics color_intrinsics, depth_intrinsics;
  double depth_scale = 5000.0;
  bool depth_registered = true;  // depth pixels align with colour pixels (same intrinsics)
  // The consumer of lit_rv / lit_r composes through Technique::compose_tiles() (the runtime
  // does): a technique may then leave the solutions undefined outside the tiles it lists.
  // False (tests and tools reading the solutions themselves): they are defined everywhere.
  bool compose_honours_tiles = false;
  // The runtime's compose output, for a technique that composes its own tiles (ComposeTiles::
  // composed): valid handles only when the runtime honours that, i.e. compose_honours_tiles is
  // set and the output has the colour camera's size (a frame whose solutions have another size
  // than the output is composed by the runtime). RGBA8 words with the virtual mask in alpha
  // (mrgi_shared.h pack_output_word), row-major at the output size; the guards of
  // mrgi_shared.h compose_encoded in linear camera units.
  gpu::BufferHandle composed_output;
  float compose_eps = 1e-3f, compose_alpha_max = 10.0f;
};

// The shared G-buffers and solutions under the names the shading shaders declare them
// (baseline/shade_direct.comp, dlpv/merge.comp): FrameUbo, real_* and virtual_* (read), lit_rv
// and lit_r (written). Without emission the albedo stands in for virtual_emission (bound, never
// read: FrameConstants::flags.y is 0).
// The frame constants and the six G-buffer images, for a pass that reads them and writes
// something of its own (dir's VPL shading).
inline void bind_gbuffer_reads(gpu::ShaderPassBuilder& b, const SharedResources& r) {
  b.bind("FrameUbo", r.frame_constants);
  b.bind("real_position", r.real_position);
  b.bind("real_normal", r.real_normal);
  b.bind("real_albedo", r.real_albedo);
  b.bind("virtual_position", r.virtual_position);
  b.bind("virtual_normal", r.virtual_normal);
  b.bind("virtual_albedo", r.virtual_albedo);
}
inline void bind_shading_gbuffers(gpu::ShaderPassBuilder& b, const SharedResources& r) {
  bind_gbuffer_reads(b, r);
  b.bind("virtual_emission", r.virtual_emission.valid() ? r.virtual_emission : r.virtual_albedo);
  b.bind("lit_rv", r.lit_rv);
  b.bind("lit_r", r.lit_r);
}

// Real geometry as a G-buffer another stage reads (the virtual G-buffer's depth test: real
// surfaces hide virtual ones): positions (xyz world, w camera depth in metres, all 0 = none)
// with one texel per `step` x `step` internal pixels, and their normals (xyz world), which a
// reader at step > 1 uses to take each pixel's depth on the texel's tangent plane
// (tangent_plane_depth, shared/mrgi_shared.h). At step 1 `normal` may be the position image.
struct RealGeometry {
  gpu::ImageHandle position, normal;
  uint32_t step = 1;
};

// This frame's caustic photons (specular/caustics.h): per spot lamp with a caustic map, the
// photons its texels sent off the mirrors and glass (two a texel: reflected, refracted) and the
// map's view, for a technique that moves the VPLs its maps put on those objects to where their
// light lands (dir: the caustics-DIR paper's Sec. 4.2.2).
struct CausticPhotons {
  struct Lamp {
    glm::vec3 position{0.0f};    // the lamp's
    glm::mat4 view_proj{1.0f};   // the photon map's view (Vulkan clip)
    uint32_t size = 0;           // its side (texels)
    gpu::BufferHandle photons;   // caustics.h Photon[2 * size * size]
  };
  std::vector<Lamp> lamps;
  // At levels with caustic receiver maps (specular.h SpecularLevel::caustic_receiver_map): the
  // maps' atlas (rgba32f, specular/caustic_receiver.glsl) and its lamps (CausticReceivers, a
  // storage buffer), for a technique whose direct shading adds the caustics to the diffuse
  // pixels' L_rv itself (then DirectLight::caustics_added). Null handles: no maps this frame.
  gpu::ImageHandle receivers;
  gpu::BufferHandle receiver_lamps;
};

// What record() needs to know about the current frame.
struct FrameInfo {
  int64_t frame_index = 0;
  int level = 0;
  bool virtual_objects_present = false;
  glm::dmat4 camera_to_world{1.0};   // this frame's pose (the previous one when none was given)
  const InputFrame* input = nullptr; // the host copy of this frame's images (valid during record)
  const CausticPhotons* caustics = nullptr;  // this frame's, written before record(); or none
};

class Technique {
 public:
  virtual ~Technique() = default;
  virtual const std::string& name() const = 0;
  virtual const std::vector<QualityLevel>& levels() const = 0;
  // Records this frame's passes for `info.level`; appends "pass: reason" for each pass left out.
  virtual Status record(const FrameInfo& info, std::vector<std::string>& skipped) = 0;
  // Whether the runtime's reconstruction (recon/: real positions, normals, albedo) runs for
  // this technique. One with its own geometry stage that reads the camera frame itself where
  // it needs it (ssrt, paper Sec. 4) says no, and the runtime records neither recon pass.
  virtual bool uses_reconstruction() const { return true; }
  // Called before the virtual G-buffer is recorded, on frames that record(): a technique whose
  // real geometry the virtual objects' depth test should use records the passes that make it
  // here and returns it from occlusion_geometry() (nullopt, the default: recon's positions).
  virtual Status record_geometry(const FrameInfo& /*info*/, std::vector<std::string>& /*skipped*/) {
    return ok_status();
  }
  virtual std::optional<RealGeometry> occlusion_geometry() const { return std::nullopt; }
  // Whether the next frame should be run twice: a technique whose output needs an estimate it
  // derives from the frames themselves (ssrt's light, read back a few frames late so nothing
  // stalls) and that has none yet asks once, so its first visible frame is not lit by a guess.
  // The runtime then records and submits the frame, waits for it, drops its output, calls
  // frames_completed() and records the frame again.
  virtual bool wants_priming_run() const { return false; }
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
  // SharedResources::composed_output (compose_encoded, the runtime's formula),
  // so compose runs no pass of its own; only where those handles are valid, for solutions at
  // the output size.
  struct ComposeTiles {
    gpu::BufferHandle args, list;
    bool composed = false;
  };
  virtual ComposeTiles compose_tiles() const { return {}; }
  // After record(): the direct light this frame's shading applied with shadow maps, for a stage
  // that lights points of its own the same way (specular/: what mirrors and glass show): the
  // light set (shaders/common/light_set.glsl, its layers index the maps) and baseline's map pair
  // (sampler2DArrayShadow), `shadow` as shade_direct.comp's LevelConstants::shadow. nullopt: this
  // frame's shading drew no shadow maps (the stage then lights its points unshadowed).
  struct DirectLight {
    gpu::BufferHandle light_set;
    gpu::ImageHandle shadow_primary, shadow_virtual;
    glm::vec4 shadow{0.0f};
    // This frame's shading added FrameInfo::caustics' receiver maps to the diffuse pixels' L_rv
    // (the stage then splats no caustics into the camera's buffer).
    bool caustics_added = false;
  };
  virtual std::optional<DirectLight> direct_light() const { return std::nullopt; }
};

using TechniqueFactory = Expected<std::unique_ptr<Technique>> (*)(const SharedResources&);
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
