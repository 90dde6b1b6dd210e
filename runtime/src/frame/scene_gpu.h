// The scene's triangle meshes on the GPU: the glTF virtual objects (for the virtual G-buffer and
// shadow maps) and the real proxy geometry of scene.json (shadow casters in the real-caster
// maps). One interleaved vertex buffer and one index buffer per set, a material array and one
// base-colour texture array for the virtual objects, all made at start-up.
//
// Virtual objects move (set_placement: an app's objects, scene.json's keyframed motion): their
// world-space vertices are rewritten from a model-space copy when a pose changes. The virtual
// vertex buffer is host-visible with one copy per frame in flight (the frame graph resolves the
// handle to the current slot's), so a frame still on the GPU keeps the poses it was recorded
// with and nothing is allocated: commit() rewrites the current slot's copy when it is older
// than the newest poses. Why world-space vertices rewritten instead of a model matrix per draw:
// every pass that reads the meshes (G-buffer, shadow maps, RSMs, the ISMs' point sampling, the
// bounce light source) reads world-space vertices, by vertex fetch and as storage buffers; one
// rewrite keeps them all right, and a pose changes at most once a frame.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/context.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "mrgi/scene.h"
#include "frame/lod_view.h"
#include "frame/surface_orientation.h"

namespace mrgi::frame {

// Vertex layout of both sets (32 bytes): world-space position, normal, texture coordinate.
struct GpuVertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};
static_assert(sizeof(GpuVertex) == 32);

struct DrawRange {
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t vertex_offset = 0;
  int32_t material = 0;  // index into the material array (virtual set only)
  // glTF doubleSided: both faces are surfaces; otherwise back faces are culled (glTF 2.0
  // 3.9.4), which on lavapipe also halves the triangles its single-threaded setup handles.
  bool double_sided = false;
  // Levels of detail, finest first: lods[0] is the range itself (error 0), each later one a
  // simplified index list of the same vertices, stored after the original indices in the same
  // buffer, with its geometric error (metres: meshoptimizer's estimate of the largest distance
  // of the simplified surface from the original). Virtual set only; empty for proxies.
  struct Lod {
    uint32_t first_index = 0;
    uint32_t index_count = 0;
    float error_m = 0.0f;
  };
  std::vector<Lod> lods;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};  // world AABB of the range's vertices
};

struct MeshSet {
  gpu::BufferHandle vertices;  // GpuVertex[]
  gpu::BufferHandle indices;   // uint32 triangle list
  std::vector<DrawRange> draws;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};  // world AABB; meaningless when empty()
  bool empty() const { return draws.empty(); }
  // Binds the buffers and draws every range; with `material_pipeline` the range's material
  // index is pushed as a 4-byte push constant at offset 0 before each draw. With
  // `double_sided_pipeline` (same layout, no culling) the ranges of double-sided materials are
  // drawn with it and the others with `material_pipeline`, each bound here when it changes.
  // With `lod` each range is drawn at the level select_lod() picks (else at full detail).
  void draw(VkCommandBuffer cmd, const gpu::PassContext& pass,
            const gpu::Pipeline* material_pipeline,
            const gpu::Pipeline* double_sided_pipeline = nullptr,
            const LodView* lod = nullptr) const;
  // The level of detail of `range` for `view` (index into range.lods; 0 without levels).
  static size_t select_lod(const DrawRange& range, const LodView& view);
};

// Base-colour textures are resampled to one square size (the largest texture side, at most
// kMaxTextureSide texels) so they fit one 2D array image; glTF texture i is layer i.
inline constexpr int kMaxTextureSide = 1024;

class SceneGpu {
 public:
  // Loads every glTF of `scene` (load_gltf) and uploads it. Errors name the glTF file.
  static Expected<std::unique_ptr<SceneGpu>> create(gpu::Context& context, gpu::FrameGraph& graph,
                                                    const SceneDesc& scene);
  ~SceneGpu();
  SceneGpu(const SceneGpu&) = delete;
  SceneGpu& operator=(const SceneGpu&) = delete;

  MeshSet virtual_objects;
  MeshSet real_proxies;

  // The virtual objects in scene.json's order, their placements, and moving them.
  size_t object_count() const { return objects_.size(); }
  const Placement& placement(size_t object) const { return objects_[object].placement; }
  // Takes effect at the next commit(). BadUsage for an index out of range, a non-finite value
  // or a scale that is not positive.
  Status set_placement(size_t object, const Placement& placement);
  // Before recording a frame: brings the current slot's vertex copy and every range's bounds
  // (and level-of-detail errors, which scale with the object) to the newest placements.
  void commit(gpu::FrameGraph& graph);
  // Shows or hides object i from the next commit() on (an app adding and removing its objects
  // within the scene's capacity). A hidden object's vertices are written 10 km below the scene,
  // outside every view, map and volume, and its ranges' bounds with them; the set's bounds are
  // the visible objects'. BadUsage for an index out of range.
  Status set_visible(size_t object, bool visible);
  bool visible(size_t object) const { return objects_[object].visible; }
  bool any_visible() const { return visible_count_ > 0; }
  // Bumped by every set_placement or set_visible that changed something: what techniques
  // compare to see that the virtual objects moved (plans fitted to their bounds).
  uint64_t revision() const { return revision_; }
  static constexpr float kHiddenDepth_m = 1.0e4f;
  gpu::BufferHandle materials;        // shader::GpuMaterial[] (at least one entry)
  bool emissive = false;              // some virtual material emits (GpuMaterial::emission)
  // Some virtual material is glossy: metallic above kGlossyMetallic or roughness below
  // kGlossyRoughness (factors; textures are not looked at). Specular work on VPLs (dir's glossy
  // VPLs) is skipped without one: a dielectric rougher than that reflects 4 % of its light in a
  // lobe broader than the VPLs' merge can tell from a cosine.
  bool glossy = false;
  static constexpr float kGlossyMetallic = 0.1f, kGlossyRoughness = 0.7f;
  gpu::ImageHandle base_color_maps;   // R8G8B8A8_SRGB array (at least one white layer)
  // Per material (the index DrawRange::material holds): shared/specular_math.h specular_kind.
  std::vector<int> material_specular_kind;
  bool specular = false;  // some virtual material reflects or refracts (specular_kind)
  // Object i's ranges in virtual_objects.draws: [first, first + count).
  struct DrawSpan {
    size_t first = 0, count = 0;
  };
  DrawSpan object_draws(size_t object) const { return {objects_[object].first_draw, objects_[object].draw_count}; }
  // Whether one of object i's ranges has a specular material, and of which kinds (bit 1 << kind).
  int object_specular_kinds(size_t object) const;
  // Sphere proxies of each object's solid (frame/occluder_spheres.h), fitted at start-up, at
  // most kOccluderSpheres an object, most important first. Appends to `out` the world-space
  // spheres (xyz centre, w radius, metres) of the visible objects at their newest placements,
  // the first `per_object` of each (the radius scaled by the placement's largest scale), and
  // with `albedo` each sphere's object's mean diffuse albedo (linear rgb; base colour x texture
  // mean x (1 - metallic), area-weighted).
  // With `object`, each sphere's object as its ordinal among the visible objects.
  static constexpr int kOccluderSpheres = 16;
  void occluder_spheres(int per_object, std::vector<glm::vec4>& out, std::vector<glm::vec4>* albedo = nullptr,
                        std::vector<int>* object = nullptr) const;
  // The `ordinal`-th visible object's surface by orientation (frame/surface_orientation.h),
  // gathered at load into at most kOrientedPatches patches, normals and areas in world space
  // (square metres) at its newest placement: written to out[0, n), n returned (0 for an
  // ordinal past the visible objects).
  static constexpr int kOrientedPatches = 8;
  int oriented_patches(size_t ordinal, OrientedPatch* out) const;

 private:
  explicit SceneGpu(gpu::Context& context) : context_(context) {}
  void write_vertices(GpuVertex* out) const;  // world space at the current placements
  void update_bounds();
  struct ObjectSpan {
    uint32_t first_vertex = 0, vertex_count = 0;
    size_t first_draw = 0, draw_count = 0;
    Placement placement;
    bool visible = true;
    std::vector<glm::vec4> occluders;  // model space, most important first
    std::vector<OrientedPatch> patches;  // model space (oriented_patches)
    glm::vec3 albedo{0.0f};            // mean diffuse albedo (occluder_spheres)
  };
  size_t visible_count_ = 0;
  gpu::Context& context_;
  std::vector<ObjectSpan> objects_;
  std::vector<GpuVertex> local_vertices_;      // model space (glTF nodes applied), all objects
  std::vector<std::vector<float>> local_lod_errors_;  // per virtual range, metres in model space
  std::vector<uint64_t> slot_revision_;        // per frame slot: the poses its vertex copy holds
  uint64_t revision_ = 0, bounds_revision_ = 0;
  gpu::GpuImage texture_array_;       // owned here, imported into the graph
};

}  // namespace mrgi::frame
