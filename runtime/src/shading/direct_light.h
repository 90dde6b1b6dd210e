// The direct-light block: the lamps' and the estimated lights' direct light on every pixel, with
// the DIR paper's real/virtual shadow-map pair per real lamp (no double shadows, eq. 1-5), the
// light stage's SH ambient, the virtual objects' emission, the specular stage's caustic receiver
// maps, and the indirect light of whichever technique runs, taken as an explicit input with its
// encoding declared (IndirectLight). It writes both solutions L_rv and L_r in one pass
// (shaders/shading/direct_light.comp):
//   L_rv += L_o * min(st_r, st_v)          (every lamp, every surface)
//   L_r  += L_o * r(lamp) * r(p) * st_r    (only real lamps on real points, real casters)
// plus the indirect input's terms (below). The `baseline` technique is this block with no
// indirect input; dir, dlpv and dvct compose it with theirs.
//
// Why the indirect light is added here and not in a pass of its own: that pass's G-buffer reads
// and read-modify-write of L_rv cost more than its lookups (5.9 ms at dlpv fast on desk_spot,
// 18 ms on corner, profiled on lavapipe).
//
// Shadow maps: allocated at 2048 for the most lights the light stage can give at start-up; lower
// levels render into and read the top-left corner, so a level change never allocates. The real
// caster mesh (the depth-camera grid drawn into the real-caster maps) has one point every
// ceil(side / (shadow_map_size / caster_cell_shadow_texels)) G-buffer pixels, side = the
// G-buffer's larger side, so its cells match what the map can resolve; it is built once a frame
// as an indexed mesh (pass shadow_caster_mesh), so each point is shaded once per face.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "frame/frame_resources.h"
#include "gpu/frame_graph.h"
#include "mrgi/expected.h"
#include "shading/environment_occlusion.h"

namespace mrgi::shading {

// One level of the block. Units as named.
struct DirectLightLevel {
  uint32_t shadow_map_size = 2048;         // texels per side of each map face (power of two, <= 2048)
  int pcf_radius = 1;                      // bilinear compare taps on each side of the centre tap
  double caster_cell_shadow_texels = 2.0;  // shadow texels a real caster grid cell spans (above)
  // Of the light stage's estimated lights (environment regions, the probeless dominant light),
  // strongest first, how many get shadow maps; the rest light as SH ambient. Declared lamps
  // always get theirs.
  int shadowed_estimated_lights = 4;
  // The virtual objects' occlusion of the ambient light (environment_occlusion.h): its grid
  // (internal pixels a texel side) and sphere proxies an object.
  EnvOcclusionLevel env_occlusion;
};

// The block's standard ladder, best first: high (2048^2 maps, 3x3 PCF, 4 shadowed estimated
// lights, environment occlusion at every pixel by 16 spheres an object), medium (1024^2, 3x3,
// 4, every 2x2 pixels by 16), low (512^2, 3x3, 2, every 4x4 by 8), lowest (256^2, one tap, 1,
// every 4x4 by 4). Each
// shadowed estimated light costs two maps and a shading term (env_fisheye, 4 at every level:
// high 461 ms, lowest 75 ms against 49 and 25 with none).
const std::array<DirectLightLevel, 4>& direct_light_levels();

// Indirect light as an image of packed radiance pairs (shaders/gi/indirect_pack.glsl: L_rv and
// L_r of a texel and its surface key, RGBA32UI), one texel per `divisor` x `divisor` internal
// pixels. Added to both solutions (L_r only on real pixels), up-sampled by bilinear weights times
// the surface test (plain bilinear where no neighbour is on the pixel's surface).
struct ScreenIndirect {
  gpu::ImageHandle packed;
  int divisor = 1;
};

// Indirect light as irradiance volumes (2-band SH per colour channel in three RGBA volumes,
// shaders/gi/volume_lookup.glsl) over a world-space grid. Added to L_rv only (the real scene's
// own bounce is in the camera image):
//   real pixel inside the grid: albedo / pi x E_real, E_real = E(real) or E(real) - E(subtract)
//   virtual pixel:              albedo x (1 - metallic) / pi x max(E(virtual_), 0)
struct VolumeIndirect {
  enum class RealTerm {
    One,         // E(real)
    Difference,  // E(real) - E(subtract)
  };
  RealTerm real_term = RealTerm::One;
  gpu::ImageHandle real[3];      // per colour channel (sampler3D)
  gpu::ImageHandle subtract[3];  // RealTerm::Difference only
  // The virtual pixels' volume, when there is one (virtual_present); the virtual pixels then take
  // it in place of the residual ambient (light_set.glsl count.y).
  gpu::ImageHandle virtual_[3];
  bool virtual_present = false;
  // shaders/gi/volume_lookup.glsl VolumeConstants.
  struct Constants {
    glm::vec4 grid;    // xyz: the volumes' min corner (m); w: cell size (m)
    glm::vec4 extent;  // x: cells allocated per side; y: cells used; z: 1 = the real term present; w: 1 = virtual_
  } constants{};
};

// A technique's indirect light for this frame: none, or one of the encodings above. The images
// must be written by passes recorded before the block's record().
using IndirectLight = std::variant<std::monostate, ScreenIndirect, VolumeIndirect>;

// What this frame's shading applied, for a stage that lights points of its own the same way
// (specular/: what mirrors and glass show): the light set (shaders/common/light_set.glsl, its
// layers index the maps), the map pair (sampler2DArrayShadow) and `shadow` as the shader's
// LevelConstants::shadow.
struct DirectLightOutput {
  gpu::BufferHandle light_set;
  gpu::ImageHandle shadow_primary, shadow_virtual;
  glm::vec4 shadow{0.0f};
  // This frame's shading added frame::FrameInfo::caustics' receiver maps to the diffuse pixels'
  // L_rv (the specular stage then splats no caustics into the camera's buffer).
  bool caustics_added = false;
};

struct DirectLightOptions {
  // A real lamp's two maps read as one holding the nearer caster and its kind (Knecht et al.
  // 2010; the dir ablation one_shadow_map): a real caster behind a virtual one no longer
  // shadows L_r (the double shadow of the DIR paper's Fig. 5).
  bool one_shadow_map = false;
  // Indirect encodings a frame may hand record(); a pipeline is made for each (lavapipe runs
  // every path a shader has, so each encoding is compiled apart).
  bool screen_indirect = false;
  bool volume_indirect = false;
};

class DirectLightBlock {
 public:
  static Expected<std::unique_ptr<DirectLightBlock>> create(const frame::FrameResources& frame,
                                                            const DirectLightOptions& options);
  ~DirectLightBlock();
  // Records this frame's shadow maps and shading at `level` with `indirect` (BadUsage for an
  // encoding the options did not ask for); appends "pass: reason" for each pass left out.
  Status record(const frame::FrameInfo& info, const DirectLightLevel& level, const IndirectLight& indirect,
                std::vector<std::string>& skipped);
  // The block's environment occlusion alone, of the light stage's ambient (real and virtual, no
  // light folded in: light::write_unshadowed_light_set's), for a technique that shades the
  // ambient itself on a frame it does not record the block (dlpv's antiradiance levels, dvct's
  // shadow cones): the pass is recorded (or left out, as record() would) and its result returned
  // for the technique's shader to read with shaders/shading/env_occlusion_lookup.glsl.
  struct EnvOcclusionResult {
    gpu::ImageHandle image;  // RGBA16F (environment_occlusion.h); a 1x1 zero image when left out
    int divisor = 0;         // internal pixels a texel side; 0 when left out
  };
  EnvOcclusionResult record_env_occlusion(const EnvOcclusionLevel& level, std::vector<std::string>& skipped);
  // A technique that records the block on some frames only calls this at the start of each
  // frame: output() then says whether this frame's shading used the block.
  void begin_frame();
  // What the block applied this frame; nullopt when begin_frame() was called and record() was
  // not since.
  std::optional<DirectLightOutput> output() const;

 private:
  struct Impl;
  explicit DirectLightBlock(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mrgi::shading
