// Reflective shadow maps (Dachsbacher & Stamminger 2005), the shared block of the VPL-based
// techniques: per lamp, a map of world positions, normals and reflected flux, one WITH the
// virtual objects (R^rho) and one without (R^mu) (DLPV paper Sec. 4.3). The real scene is the
// depth camera's (a grid over the real G-buffer, the casters of the direct-light block's shadow maps) and the
// scene's proxy meshes; the virtual objects are their glTF meshes and materials.
//
// Maps are allocated at create() for `size` texels per side and drawn at a used size per frame
// (a cheaper level draws a corner). One pair of maps serves every lamp in turn: the frame graph
// orders each lamp's injection before the next lamp's drawing.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/light_propagation.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "mrgi/scene.h"
#include "frame/scene_gpu.h"

namespace mrgi::gi {

struct RsmSettings {
  std::string name = "rsm";
  uint32_t size = 512;  // texels per side allocated (the largest level), 16..2048
};

// The real scene's G-buffer the grid is drawn from (recon/): positions (xyz, w depth; 0 none),
// normals, albedo (rgb, a valid).
struct RealGBuffer {
  gpu::ImageHandle position, normal, albedo;
};

// One lamp's view for its maps, covering a sphere (the volume the maps feed).
struct RsmView {
  glm::mat4 view_proj{1.0f};
  glm::vec4 light{0.0f};  // as gi/rsm.frag's push constant `light`
  glm::vec4 colour{0.0f};
  glm::vec4 axis{0.0f};
  LpvLight lpv;           // the same lamp for the injection
  // The virtual meshes' level of detail as the map sees them: the coarsest whose error stays
  // within half a map texel (a finer mesh adds triangles no texel resolves).
  frame::LodView lod;
};
// BadUsage for a lamp the maps cannot see the sphere from (a point lamp inside it: its light
// leaves in every direction, which one perspective map cannot hold).
Expected<RsmView> rsm_view(const LightDesc& lamp, const glm::vec3& centre, float radius, uint32_t size);

// Whether the lamp's light can reach the sphere: false only for a spot lamp whose outer cone
// misses it (its light then meets no virtual object in it).
bool lamp_reaches_sphere(const LightDesc& lamp, const glm::vec3& centre, float radius);

enum class RsmMap : uint8_t { WithVirtual, RealOnly };

// The push block of gi/rsm_grid.vert and gi/rsm_mesh.vert (and the fragment shaders drawn with
// them: gi/rsm.frag, the specular stage's impostor, back-face and photon-surface shaders).
struct RsmPush {
  glm::mat4 view_proj{1.0f};
  glm::vec4 light{0.0f};
  glm::vec4 colour{0.0f};
  glm::vec4 axis{0.0f};
  glm::ivec4 misc{1, -1, 0, 0};  // x grid stride; y the draw's material (-1: proxy); z a proxy's hint colour; w grid points per row
};
static_assert(sizeof(RsmPush) == 128, "the guaranteed push-constant size");

// The scene as the RSM vertex shaders draw it, inside a render pass that is begun, with its
// viewport set: the real grid over the real G-buffer (an index list drawn directly, or from an
// indexed indirect command), the proxies (their material hint: mid grey) and the virtual meshes
// with their materials, at `lod` (else full detail), leaving out the virtual ranges `skip` marks.
struct RsmGeometryDraw {
  const gpu::Pipeline* grid_pipeline = nullptr;  // null: no real grid
  const gpu::Pipeline* mesh_pipeline = nullptr;  // null: no meshes
  RealGBuffer real;
  gpu::BufferHandle grid_indices;
  uint32_t grid_index_count = 0;               // a direct draw of this many indices, or
  gpu::BufferHandle grid_indirect;             // valid: one VkDrawIndexedIndirectCommand at
  VkDeviceSize grid_indirect_offset = 0;       // this offset
  bool proxies = true, virtuals = true;
  const std::vector<bool>* skip_virtual = nullptr;
  const frame::LodView* lod = nullptr;
  // Set: ranges (proxies and virtual objects) whose bounds lie wholly outside one plane of this
  // view's clip volume are not drawn (lavapipe sets up every triangle of a draw on one thread,
  // culled or not: the six faces of an impostor cube each see one or two of the objects).
  const glm::mat4* cull_view_proj = nullptr;
};
void draw_rsm_geometry(VkCommandBuffer cmd, gpu::PassContext& p, const frame::SceneGpu& scene,
                       const RsmGeometryDraw& draw, RsmPush push);

class ReflectiveShadowMaps {
 public:
  static Expected<ReflectiveShadowMaps> create(gpu::FrameGraph& graph, const frame::SceneGpu& scene,
                                               const RealGBuffer& real, const RsmSettings& settings);
  // The real grid's index list for this frame (call once a frame before add_pair, when the real
  // G-buffer changed): `stride` G-buffer pixels between grid points.
  void add_grid(gpu::FrameGraph& graph, uint32_t stride);
  // Draws the pair for `view` at `size` texels per side (<= the allocated size): R^mu (the real
  // casters), then R^rho as R^mu's copy with the virtual objects drawn over it, so the real
  // casters are drawn once and the texels no virtual object covers are equal bit for bit in
  // both maps (a delta injection leaves them out: LightPropagationVolume::add_inject's `other`).
  // Passes "<name> mu <id>", "<name> rho copy <id>", "<name> rho <id>".
  void add_pair(gpu::FrameGraph& graph, const std::string& id, const RsmView& view, uint32_t size);
  // R^mu alone (pass "<name> mu <id>"), for a lamp whose light reaches no virtual object
  // (sees_sphere): R^rho would be its copy; read R^mu as both.
  void add_real(gpu::FrameGraph& graph, const std::string& id, const RsmView& view, uint32_t size);
  // The map as the injection reads it.
  RsmImages images(RsmMap map, uint32_t size) const;
  uint32_t allocated_size() const { return settings_.size; }

 private:
  ReflectiveShadowMaps() = default;
  struct Maps {
    gpu::ImageHandle position, normal, flux, depth;
  };
  void add_map_draw(gpu::FrameGraph& graph, const std::string& label, const RsmView& view, const Maps& m,
                    uint32_t size, bool real_casters, bool virtual_casters);
  RsmSettings settings_;
  const frame::SceneGpu* scene_ = nullptr;
  RealGBuffer real_;
  Maps maps_[2];
  gpu::BufferHandle grid_indices_;
  uint32_t grid_stride_ = 0;
  VkExtent2D grid_points_{0, 0};
  gpu::PipelineHandle grid_pipeline_, mesh_pipeline_, indices_pipeline_;
};

}  // namespace mrgi::gi
