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
//
// Objects come and go within a room stated at start-up (ObjectCapacity: an app placing its
// objects, add_object / remove_object): the virtual set's indices, materials and triangle list
// are host-visible per frame slot too, all sized for scene.json's objects plus the room, and
// the present objects are packed into them in slot order (a removed object's room is free at
// once; a frame on the GPU keeps its slot's lists). Textures take free layers of the array.
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
#include "common/scene_materials.glsl"

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

// Base-colour and emissive textures are resampled to one square size (the largest texture side,
// at most kMaxTextureSide texels) so they fit one 2D array image, a layer each (scene.json's in
// order, then the room's, taken from a free list).
inline constexpr int kMaxTextureSide = 1024;

// The virtual meshes' triangles at full detail as shaders/gi/virtual_points.glsl reads them
// (the ISMs' point sampling, dir's bounce light source): one entry per draw range with
// triangles. Host-visible, one copy per frame in flight, rewritten with the meshes.
struct VirtualTriangles {
  gpu::BufferHandle ranges;     // ivec4 per draw range: first index, triangles, vertex offset, triangles before
  gpu::BufferHandle materials;  // int per draw range: its material
  uint32_t triangles = 0;       // over every range
  uint32_t range_count = 0;     // ranges with triangles (the buffers hold at least one entry)
};

// One object's meshes as loaded, in model space, before they are packed with the others
// (frame/scene_objects.cpp): what add_object prepares off the frame loop.
struct ObjectMeshes {
  std::vector<GpuVertex> vertices;     // model space (glTF nodes applied)
  std::vector<uint32_t> indices;       // every range's, levels of detail included, from 0
  std::vector<DrawRange> draws;        // first_index, lods and vertex_offset relative to the
                                       // object's; material: index into `materials`, -1 = default
  std::vector<std::vector<float>> lod_errors;  // per range, metres in model space
  std::vector<Material> materials;     // the glTF's (texture indices into `textures`)
  std::vector<const ImageRGBA8*> textures;  // into the Model it was made from
  std::vector<glm::vec4> occluders;    // sphere proxies, model space, most important first
  std::vector<OrientedPatch> patches;  // model space (oriented_patches)
  glm::vec3 albedo{0.0f};              // mean diffuse albedo (occluder_spheres)
  uint32_t triangles = 0;              // at full detail
};
// The object's meshes from a loaded model (placement not applied): ranges with their levels of
// detail, sphere proxies, orientation patches and mean albedo.
ObjectMeshes object_meshes(const Model& model);
// Appends a primitive's vertices (normals up and uv 0 where it has none) and indices: its range
// (first index, count, vertex offset, bounds; no material, no levels of detail).
DrawRange append_primitive(const MeshPrimitive& prim, std::vector<GpuVertex>& vertices, std::vector<uint32_t>& indices);

class SceneGpu {
 public:
  // Loads every glTF of `scene` (load_gltf) and uploads it, with room for the objects `room`
  // allows beside them (add_object). Errors name the glTF file.
  static Expected<std::unique_ptr<SceneGpu>> create(gpu::Context& context, gpu::FrameGraph& graph,
                                                    const SceneDesc& scene, const ObjectCapacity& room = {});
  ~SceneGpu();
  SceneGpu(const SceneGpu&) = delete;
  SceneGpu& operator=(const SceneGpu&) = delete;

  // The present objects' ranges, packed in slot order (DrawRange::material indexes
  // `materials`); the buffers hold one copy per frame in flight, brought to the host's lists
  // by commit() when the current slot's copy is older.
  MeshSet virtual_objects;
  MeshSet real_proxies;

  // The object slots: scene.json's objects in its order, then the room's (ObjectCapacity::
  // objects). A slot holds an object (present) or is empty.
  size_t object_count() const { return objects_.size(); }
  bool present(size_t object) const { return object < objects_.size() && objects_[object].present; }
  size_t present_count() const {
    size_t n = 0;
    for (const ObjectSpan& o : objects_) n += o.present ? 1 : 0;
    return n;
  }
  const Placement& placement(size_t object) const { return objects_[object].placement; }
  // Takes effect at the next commit(). BadUsage for an index out of range or an empty slot, a
  // non-finite value or a scale that is not positive.
  Status set_placement(size_t object, const Placement& placement);
  // Before recording a frame: brings the current slot's copies (vertices at the newest
  // placements; after an add or remove also indices, materials and the triangle list) and
  // every range's bounds (and level-of-detail errors, which scale with the object) up to date.
  void commit(gpu::FrameGraph& graph);
  // Shows or hides object i from the next commit() on (its room kept). A hidden object's
  // vertices are written 10 km below the scene, outside every view, map and volume, and its
  // ranges' bounds with them; the set's bounds are the visible objects'. BadUsage for an index
  // out of range or an empty slot.
  Status set_visible(size_t object, bool visible);
  bool visible(size_t object) const { return objects_[object].present && objects_[object].visible; }
  bool any_visible() const { return visible_count_ > 0; }
  // Puts `model` (model space: load_gltf with an identity placement) in the first empty slot
  // at `placement`, shown from the next commit() on; returns the slot. Its textures are copied
  // into free layers of the array now, a transfer each, ordered after the frames in flight and
  // waited for on its own fence (Context::upload_image_layer). BadUsage
  // naming `what` and the capacity that is full, or a material the scene was not prepared for;
  // nothing changes on an error.
  Expected<size_t> add_object(const Model& model, const Placement& placement, const std::string& what);
  // Empties slot i from the next commit() on; its room is free. BadUsage for an index out of
  // range or an empty slot.
  Status remove_object(size_t object);
  // Whether the scene may hold virtual objects at all (scene.json's or room for added ones):
  // what the stages that exist only for objects are made for at start-up.
  bool may_have_objects() const { return may_have_objects_; }
  // Bumped by every set_placement, set_visible, add_object or remove_object that changed
  // something: what techniques compare to see that the virtual objects moved (plans fitted
  // to their bounds, voxelisations, reused VPLs).
  uint64_t revision() const { return revision_; }
  // Bumped by add_object and remove_object: the ranges, materials and triangle list changed.
  uint64_t layout_revision() const { return layout_revision_; }
  static constexpr float kHiddenDepth_m = 1.0e4f;
  gpu::BufferHandle materials;        // shader::GpuMaterial[] (at least one entry), per frame slot
  // Whether a virtual material may emit (GpuMaterial::emission) or be glossy (metallic above
  // kGlossyMetallic or roughness below kGlossyRoughness; factors, textures are not looked at):
  // scene.json's or the room's (ObjectCapacity::emissive, glossy). Fixed at start-up: what
  // passes are made for. Specular work on VPLs (dir's glossy VPLs) is made only for a glossy
  // scene: a dielectric rougher than that reflects 4 % of its light in a lobe broader than the
  // VPLs' merge can tell from a cosine.
  bool emissive = false;
  bool glossy = false;
  // Whether a present object's material is glossy now (for work chosen per frame).
  bool has_glossy() const { return glossy_now_; }
  static constexpr float kGlossyMetallic = 0.1f, kGlossyRoughness = 0.7f;
  gpu::ImageHandle base_color_maps;   // R8G8B8A8_SRGB array (at least one white layer)
  // Per material (the index DrawRange::material holds): shared/specular_math.h specular_kind.
  std::vector<int> material_specular_kind;
  bool specular = false;  // some virtual material reflects or refracts (specular_kind)
  // The present objects' triangle list (VirtualTriangles), current for this frame's slot.
  const VirtualTriangles& virtual_triangles() const { return triangles_; }
  // Object i's ranges in virtual_objects.draws: [first, first + count) (none for an empty slot).
  struct DrawSpan {
    size_t first = 0, count = 0;
  };
  DrawSpan object_draws(size_t object) const { return {objects_[object].first_draw, objects_[object].draw_count}; }
  // Whether one of object i's ranges has a specular material, and of which kinds (bit 1 << kind).
  int object_specular_kinds(size_t object) const;
  // Sphere proxies of each object's solid (frame/occluder_spheres.h), fitted when it is loaded, at
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
  struct ObjectSpan {
    bool present = false;
    bool visible = true;
    Placement placement;
    ObjectMeshes meshes;
    std::vector<shader::GpuMaterial> materials;  // texture layers resolved into the array
    std::vector<int> material_kinds;             // specular_kind per material
    std::vector<uint32_t> layers;                // texture array layers it holds
    // Where pack() put it: its first vertex, range and material in the packed lists.
    uint32_t first_vertex = 0, vertex_count = 0;
    size_t first_draw = 0, draw_count = 0;
  };
  // The slot's materials from the glTF's, textures at `layers` (the glTF's texture order).
  void set_materials(ObjectSpan& span, const std::vector<uint32_t>& layers) const;
  // The totals the packed lists would have with `extra` added: what the buffers must hold.
  struct Totals {
    size_t vertices = 0, triangles = 0, indices = 0, draws = 0, materials = 1;
  };
  Totals totals(const ObjectMeshes* extra) const;
  // The present objects' lists packed in slot order: vertices (model space), indices,
  // ranges, materials and the triangle list; bumps both revisions.
  void pack();
  void write_vertices(GpuVertex* out) const;  // world space at the current placements
  void update_bounds();
  // Copies `model`'s textures, resampled to the array's side, into `layers`.
  Status upload_layers(const std::vector<const ImageRGBA8*>& textures, const std::vector<uint32_t>& layers);
  size_t visible_count_ = 0;
  gpu::Context& context_;
  std::vector<ObjectSpan> objects_;
  size_t scene_objects_ = 0;                   // scene.json's (the first slots)
  bool may_have_objects_ = false;
  bool glossy_now_ = false;
  // The packed lists (pack()), written into each slot's copies by commit().
  std::vector<GpuVertex> local_vertices_;      // model space
  std::vector<uint32_t> packed_indices_;
  std::vector<std::vector<float>> local_lod_errors_;  // per virtual range, metres in model space
  std::vector<shader::GpuMaterial> packed_materials_;
  std::vector<glm::ivec4> packed_ranges_;      // VirtualTriangles::ranges
  std::vector<int32_t> packed_range_materials_;
  Totals capacity_;                            // what the buffers hold
  std::vector<uint64_t> slot_revision_;        // per frame slot: the poses its vertex copy holds
  std::vector<uint64_t> slot_layout_;          // per frame slot: the layout its other copies hold
  uint64_t revision_ = 0, bounds_revision_ = 0, layout_revision_ = 0;
  VirtualTriangles triangles_;
  uint32_t texture_side_ = 1;
  std::vector<uint32_t> free_layers_;          // texture array layers no object holds
  gpu::GpuImage texture_array_;       // owned here, imported into the graph
  gpu::GpuBuffer texture_staging_;    // one layer, for add_object (none without room for textures)
};

}  // namespace mrgi::frame
