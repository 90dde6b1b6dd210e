// The frame layer: what every stage of a frame shares (reconstruction, light, G-buffers, GI
// blocks, direct light, the specular stage, the techniques). Below all of them: nothing here
// knows a technique. The runtime owns one FrameResources for its life and hands it to every
// stage it creates; the FrameInfo of each frame to every stage it records.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "frame/camera_view.h"
#include "gpu/frame_graph.h"
#include "mrgi/frame.h"
#include "mrgi/runtime.h"
#include "mrgi/scene.h"

namespace mrgi::gpu {
class Context;
}
namespace mrgi::light {
class LightStage;
}

namespace mrgi::frame {

// The start-up inputs of every stage (owned by the runtime, alive as long as it).
class SceneGpu;
struct FrameResources {
  gpu::Context* context = nullptr;
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
  // This frame's raw inputs as uploaded by recon/ (per-slot buffers): colour sRGB8 as one word
  // a pixel (recon/reconstruction.h kColorWordBytes; colour intrinsics' size), depth u16 (depth
  // intrinsics' size, depth_scale units per metre, 0 = no measurement), and the cameras they
  // come from.
  gpu::BufferHandle color_upload, depth_upload;
  Intrinsics color_intrinsics, depth_intrinsics;
  double depth_scale = 5000.0;
  bool depth_registered = true;  // depth pixels align with colour pixels (same intrinsics)
  // The consumer of lit_rv / lit_r composes through Technique::compose_tiles() (the runtime
  // does): a technique may then leave the solutions undefined outside the tiles it lists.
  // False (tests and tools reading the solutions themselves, or a stage after the technique
  // that reads them at any pixel: the specular stage): they are defined everywhere.
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
// (shading/direct_light.comp, dlpv/merge.comp): FrameUbo, real_* and virtual_* (read), lit_rv
// and lit_r (written). Without emission the albedo stands in for virtual_emission (bound, never
// read: FrameConstants::flags.y is 0).
// The frame constants and the six G-buffer images, for a pass that reads them and writes
// something of its own (dir's VPL shading).
inline void bind_gbuffer_reads(gpu::ShaderPassBuilder& b, const FrameResources& r) {
  b.bind("FrameUbo", r.frame_constants);
  b.bind("real_position", r.real_position);
  b.bind("real_normal", r.real_normal);
  b.bind("real_albedo", r.real_albedo);
  b.bind("virtual_position", r.virtual_position);
  b.bind("virtual_normal", r.virtual_normal);
  b.bind("virtual_albedo", r.virtual_albedo);
}
inline void bind_shading_gbuffers(gpu::ShaderPassBuilder& b, const FrameResources& r) {
  bind_gbuffer_reads(b, r);
  b.bind("virtual_emission", r.virtual_emission.valid() ? r.virtual_emission : r.virtual_albedo);
  b.bind("lit_rv", r.lit_rv);
  b.bind("lit_r", r.lit_r);
}

// Real geometry as a G-buffer another stage reads (the virtual G-buffer's depth test: real
// surfaces hide virtual ones): positions (xyz world, w camera depth in metres, all 0 = none)
// with one texel per `step` x `step` internal pixels, and their normals (xyz world), which a
// reader whose pixels are finer than the texels (step > 1, or the output-resolution coverage
// below the internal size) uses to take each pixel's depth on the texel's tangent plane
// (tangent_plane_depth, shared/mrgi_shared.h).
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
  // The camera as the host sees it (frame/camera_view.h: this frame's images, or for frames
  // given as the app's images an earlier frame's); valid during record. Null: none.
  const CameraView* camera = nullptr;
  const CausticPhotons* caustics = nullptr;  // this frame's, written before record(); or none
  // The internal pixels where a virtual pixel can be this frame (recon::VirtualGBuffer::
  // objects_area); outside it every pixel is real, so a pass may run a variant without the
  // virtual surfaces' code there. nullopt: not known (every pixel may be virtual).
  std::optional<VkRect2D> virtual_area;
};

}  // namespace mrgi::frame
