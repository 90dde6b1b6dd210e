#include "frame/scene_gpu.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#define STB_IMAGE_RESIZE_STATIC
#define STB_IMAGE_RESIZE_IMPLEMENTATION
#include <stb/stb_image_resize.h>

#include "shared/specular_math.h"
#include "gpu/vk_check.h"

namespace mrgi::frame {
namespace {

// The real proxies: world space (their placement applied by load_gltf), no levels of detail,
// material 0; device-local, uploaded once.
struct ProxyData {
  std::vector<GpuVertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<DrawRange> draws;
  glm::vec3 lo{1e30f}, hi{-1e30f};
};

void append_proxy(const Model& model, ProxyData& out) {
  for (const MeshPrimitive& prim : model.primitives) {
    if (prim.indices.empty() || prim.positions.empty()) continue;
    const DrawRange range = append_primitive(prim, out.vertices, out.indices);
    out.lo = glm::min(out.lo, range.bounds_min);
    out.hi = glm::max(out.hi, range.bounds_max);
    out.draws.push_back(range);
  }
}

Expected<MeshSet> upload_proxies(gpu::Context& ctx, gpu::FrameGraph& graph, const ProxyData& data) {
  MeshSet set;
  // Never zero-sized (Vulkan forbids it); an empty set simply has no draws. Storage too:
  // compute passes read the meshes as lists (gi/voxelize.h).
  const VkDeviceSize vbytes = std::max<VkDeviceSize>(64, data.vertices.size() * sizeof(GpuVertex));
  const VkDeviceSize ibytes = std::max<VkDeviceSize>(64, data.indices.size() * sizeof(uint32_t));
  const VkBufferUsageFlags common = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  auto vb = graph.create_buffer({"real_proxies_vertices", vbytes}, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | common);
  if (!vb) return vb.error();
  auto ib = graph.create_buffer({"real_proxies_indices", ibytes}, VK_BUFFER_USAGE_INDEX_BUFFER_BIT | common);
  if (!ib) return ib.error();
  if (!data.vertices.empty()) {
    MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(*vb, 0), data.vertices.data(), data.vertices.size() * sizeof(GpuVertex)));
    MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(*ib, 0), data.indices.data(), data.indices.size() * sizeof(uint32_t)));
  }
  set.vertices = *vb;
  set.indices = *ib;
  set.draws = data.draws;
  if (!data.draws.empty()) {
    set.bounds_min = data.lo;
    set.bounds_max = data.hi;
  }
  return set;
}

// A host-visible buffer with one copy per frame in flight (never zero-sized).
Expected<gpu::BufferHandle> per_slot_buffer(gpu::FrameGraph& graph, const std::string& name, size_t bytes,
                                            VkBufferUsageFlags usage) {
  gpu::BufferDesc d{name, std::max<VkDeviceSize>(64, VkDeviceSize(bytes))};
  d.memory = gpu::MemoryUsage::Upload;
  d.per_frame_copies = true;
  return graph.create_buffer(d, usage);
}

// glTF's default material (white, metallic 1, roughness 1 per the spec): material 0.
const shader::GpuMaterial kDefaultMaterial{glm::vec4(1.0f), glm::vec4(1.0f, 1.0f, -1.0f, 0.0f), glm::vec4(0.0f),
                                           glm::vec4(0.0f, 1.5f, 0.0f, 0.0f), glm::vec4(1.0f)};

bool glossy_material(const Material& m) {
  return m.metallic > SceneGpu::kGlossyMetallic || m.roughness < SceneGpu::kGlossyRoughness;
}
bool emissive_material(const Material& m) { return m.emissive.x > 0.0f || m.emissive.y > 0.0f || m.emissive.z > 0.0f; }

Status check_placement(size_t object, const Placement& p) {
  const glm::vec4 q(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w);
  bool finite = true;
  for (int i = 0; i < 3; ++i) finite = finite && std::isfinite(p.position[i]) && std::isfinite(p.scale[i]);
  for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(q[i]);
  if (!finite || !(glm::length(q) > 1e-6f))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) +
                                         ": placement must be finite with a non-zero rotation quaternion");
  if (!(p.scale.x > 0.0f && p.scale.y > 0.0f && p.scale.z > 0.0f))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) + ": scale must be positive");
  return ok_status();
}

Status check_room(const ObjectCapacity& room) {
  auto bad = [](const std::string& field, const std::string& rule) {
    return fail(ErrorKind::BadUsage, "RuntimeSettings::objects." + field + ": " + rule);
  };
  if (room.objects < 0 || room.objects > 4096) return bad("objects", "must be 0..4096");
  if (room.meshes < 0 || room.meshes > 65536) return bad("meshes", "must be 0..65536");
  if (room.textures < 0 || room.textures > 256) return bad("textures", "must be 0..256");
  if (room.triangles > (1u << 24)) return bad("triangles", "must be at most 16777216");
  if (room.vertices > (1u << 24)) return bad("vertices", "must be at most 16777216");
  if (room.texture_side < 1 || room.texture_side > kMaxTextureSide)
    return bad("texture_side", "must be 1.." + std::to_string(kMaxTextureSide) + " texels");
  if (room.objects == 0 && (room.meshes > 0 || room.triangles > 0 || room.vertices > 0 || room.textures > 0))
    return bad("objects", "is 0 while meshes, triangles, vertices or textures are not: no object could use them");
  return ok_status();
}

}  // namespace

size_t MeshSet::select_lod(const DrawRange& range, const LodView& view) {
  // Nearest point of the range's bounds: its error can be seen no larger anywhere.
  const glm::vec3 nearest = glm::clamp(view.camera_world, range.bounds_min, range.bounds_max);
  const float distance = glm::length(nearest - view.camera_world);
  size_t chosen = 0;
  if (!(view.max_error_px > 0.0f)) return chosen;  // full detail asked for
  for (size_t i = 1; i < range.lods.size(); ++i) {
    const float px = distance > 0.0f ? range.lods[i].error_m * view.focal_px / distance : 1e30f;
    if (!(px <= view.max_error_px)) break;
    chosen = i;
  }
  return chosen;
}

void MeshSet::draw(VkCommandBuffer cmd, const gpu::PassContext& pass,
                   const gpu::Pipeline* material_pipeline,
                   const gpu::Pipeline* double_sided_pipeline, const LodView* lod) const {
  if (draws.empty()) return;
  VkBuffer vb = pass.buffer(vertices);
  VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
  vkCmdBindIndexBuffer(cmd, pass.buffer(indices), 0, VK_INDEX_TYPE_UINT32);
  const gpu::Pipeline* bound = nullptr;
  for (const DrawRange& d : draws) {
    if (double_sided_pipeline) {
      const gpu::Pipeline* want = d.double_sided ? double_sided_pipeline : material_pipeline;
      if (want != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, want->pipeline);
      bound = want;
    }
    if (material_pipeline)
      vkCmdPushConstants(cmd, material_pipeline->layout, material_pipeline->stages, 0,
                         sizeof(int32_t), &d.material);
    if (lod && !d.lods.empty()) {
      const DrawRange::Lod& l = d.lods[select_lod(d, *lod)];
      vkCmdDrawIndexed(cmd, l.index_count, 1, l.first_index, d.vertex_offset, 0);
    } else {
      vkCmdDrawIndexed(cmd, d.index_count, 1, d.first_index, d.vertex_offset, 0);
    }
  }
}

void SceneGpu::occluder_spheres(int per_object, std::vector<glm::vec4>& out, std::vector<glm::vec4>* albedo,
                                std::vector<int>* object) const {
  int ordinal = 0;
  for (const ObjectSpan& o : objects_) {
    if (!o.visible) continue;
    const int this_object = ordinal++;
    const glm::mat4 m = o.placement.matrix();
    const float grow = std::max({o.placement.scale.x, o.placement.scale.y, o.placement.scale.z});
    const size_t n = std::min(o.meshes.occluders.size(), size_t(std::max(per_object, 0)));
    for (size_t k = 0; k < n; ++k) {
      out.emplace_back(glm::vec3(m * glm::vec4(glm::vec3(o.meshes.occluders[k]), 1.0f)), o.meshes.occluders[k].w * grow);
      if (albedo) albedo->emplace_back(o.meshes.albedo, 0.0f);
      if (object) object->push_back(this_object);
    }
  }
}

int SceneGpu::oriented_patches(size_t ordinal, OrientedPatch* out) const {
  size_t seen = 0;
  for (const ObjectSpan& o : objects_) {
    if (!o.visible || seen++ != ordinal) continue;
    // Normals by the inverse transpose of the placement's linear part (a non-uniform scale
    // tilts them); areas as area vectors, by the cofactor matrix det(M) M^-T: square metres.
    const glm::mat3 linear(o.placement.matrix());
    const glm::mat3 normals = glm::transpose(glm::inverse(linear));
    const float det = std::abs(glm::determinant(linear));
    const int n = int(std::min(o.meshes.patches.size(), size_t(kOrientedPatches)));
    for (int k = 0; k < n; ++k) {
      out[k] = o.meshes.patches[size_t(k)];
      const glm::vec3 w = normals * o.meshes.patches[size_t(k)].normal;
      out[k].normal = glm::length(w) > 0.0f ? glm::normalize(w) : o.meshes.patches[size_t(k)].normal;
      const float to_world = std::isfinite(det) ? det * glm::length(w) : 0.0f;
      out[k].area = o.meshes.patches[size_t(k)].area * to_world;
      out[k].facing_area = o.meshes.patches[size_t(k)].facing_area * to_world;
    }
    return n;
  }
  return 0;
}

void SceneGpu::set_materials(ObjectSpan& span, const std::vector<uint32_t>& layers) const {
  span.materials.clear();
  span.material_kinds.clear();
  auto layer_of = [&](int texture) {
    return texture >= 0 && size_t(texture) < layers.size() ? float(layers[size_t(texture)]) : -1.0f;
  };
  for (const Material& mat : span.meshes.materials) {
    const int kind = shader::specular_kind(mat.metallic, mat.roughness, mat.transmission);
    span.materials.push_back({mat.base_color_factor, glm::vec4(mat.metallic, mat.roughness, layer_of(mat.base_color_texture), 0.0f),
                              glm::vec4(glm::max(mat.emissive, glm::vec3(0.0f)), layer_of(mat.emissive_texture)),
                              glm::vec4(float(kind), mat.ior, mat.attenuation_distance, mat.transmission),
                              glm::vec4(mat.attenuation_color, 0.0f)});
    span.material_kinds.push_back(kind);
  }
}

SceneGpu::Totals SceneGpu::totals(const ObjectMeshes* extra) const {
  Totals t;
  auto add = [&](const ObjectMeshes& m) {
    t.vertices += m.vertices.size();
    t.triangles += m.triangles;
    t.indices += m.indices.size();
    t.draws += m.draws.size();
    t.materials += m.materials.size();
  };
  for (const ObjectSpan& o : objects_)
    if (o.present) add(o.meshes);
  if (extra) add(*extra);
  return t;
}

void SceneGpu::pack() {
  local_vertices_.clear();
  packed_indices_.clear();
  local_lod_errors_.clear();
  virtual_objects.draws.clear();
  packed_materials_.assign(1, kDefaultMaterial);
  material_specular_kind.assign(1, 0);
  packed_ranges_.clear();
  packed_range_materials_.clear();
  glossy_now_ = false;
  uint32_t triangles_before = 0;
  for (ObjectSpan& o : objects_) {
    o.first_vertex = uint32_t(local_vertices_.size());
    o.first_draw = virtual_objects.draws.size();
    o.vertex_count = 0;
    o.draw_count = 0;
    if (!o.present) continue;
    const uint32_t index_base = uint32_t(packed_indices_.size());
    const int material_base = int(packed_materials_.size());
    local_vertices_.insert(local_vertices_.end(), o.meshes.vertices.begin(), o.meshes.vertices.end());
    packed_indices_.insert(packed_indices_.end(), o.meshes.indices.begin(), o.meshes.indices.end());
    for (size_t r = 0; r < o.meshes.draws.size(); ++r) {
      DrawRange d = o.meshes.draws[r];
      d.first_index += index_base;
      for (DrawRange::Lod& l : d.lods) l.first_index += index_base;
      d.vertex_offset += int32_t(o.first_vertex);
      d.material = d.material < 0 ? 0 : material_base + d.material;
      const uint32_t triangles = d.index_count / 3;
      if (triangles > 0) {
        packed_ranges_.emplace_back(int(d.first_index), int(triangles), d.vertex_offset, int(triangles_before));
        packed_range_materials_.push_back(d.material);
        triangles_before += triangles;
      }
      virtual_objects.draws.push_back(std::move(d));
      local_lod_errors_.push_back(o.meshes.lod_errors[r]);
    }
    packed_materials_.insert(packed_materials_.end(), o.materials.begin(), o.materials.end());
    material_specular_kind.insert(material_specular_kind.end(), o.material_kinds.begin(), o.material_kinds.end());
    for (const Material& m : o.meshes.materials) glossy_now_ = glossy_now_ || glossy_material(m);
    o.vertex_count = uint32_t(local_vertices_.size()) - o.first_vertex;
    o.draw_count = virtual_objects.draws.size() - o.first_draw;
  }
  triangles_.triangles = triangles_before;
  triangles_.range_count = uint32_t(packed_ranges_.size());
  ++revision_;
  ++layout_revision_;
}

Expected<std::unique_ptr<SceneGpu>> SceneGpu::create(gpu::Context& context, gpu::FrameGraph& graph,
                                                     const SceneDesc& scene, const ObjectCapacity& room) {
  MRGI_TRY(check_room(room));
  std::unique_ptr<SceneGpu> out(new SceneGpu(context));
  std::vector<Model> models;  // kept until the textures are uploaded
  models.reserve(scene.virtual_objects.size());
  for (const VirtualObjectDesc& obj : scene.virtual_objects) {
    // Model space (the placement is applied per frame, commit()); checked like set_placement.
    auto model = load_gltf(obj.gltf, Placement{});
    if (!model) return model.error();
    models.push_back(std::move(*model));
  }
  out->scene_objects_ = models.size();
  out->may_have_objects_ = !models.empty() || room.objects > 0;
  out->objects_.resize(models.size() + size_t(room.objects));
  for (ObjectSpan& o : out->objects_) o.visible = false;
  std::vector<const ImageRGBA8*> textures;
  uint32_t side = room.textures > 0 ? uint32_t(room.texture_side) : 1;
  for (size_t i = 0; i < models.size(); ++i) {
    ObjectSpan& span = out->objects_[i];
    span.meshes = object_meshes(models[i]);
    for (const ImageRGBA8* t : span.meshes.textures) {
      span.layers.push_back(uint32_t(textures.size()));
      textures.push_back(t);
      side = std::max<uint32_t>(side, uint32_t(std::max(t->width, t->height)));
    }
    span.meshes.textures.clear();
    out->set_materials(span, span.layers);
    for (const Material& m : span.meshes.materials) {
      out->glossy = out->glossy || glossy_material(m);
      out->emissive = out->emissive || emissive_material(m);
    }
    for (int kind : span.material_kinds) out->specular = out->specular || kind != shader::SPECULAR_NONE;
    span.present = span.visible = true;
    MRGI_TRY(check_placement(i, scene.virtual_objects[i].placement));  // refuses a bad scene.json pose
    span.placement = scene.virtual_objects[i].placement;
  }
  out->glossy = out->glossy || room.glossy;
  out->emissive = out->emissive || room.emissive;
  out->visible_count_ = models.size();
  out->texture_side_ = std::min<uint32_t>(side, kMaxTextureSide);
  const uint32_t layers = std::max<uint32_t>(1, uint32_t(textures.size()) + uint32_t(room.textures));
  // The room's layers, lowest last (taken first). Not the white stand-in layer of a scene with
  // no texture and no room for one.
  for (uint32_t l = uint32_t(textures.size()) + uint32_t(room.textures); l-- > uint32_t(textures.size());)
    out->free_layers_.push_back(l);

  // The buffers: scene.json's objects and the room (its levels of detail at most as many
  // indices again as its triangles' own).
  Totals cap = out->totals(nullptr);
  cap.vertices += room.vertices;
  cap.triangles += room.triangles;
  cap.indices += size_t(room.triangles) * 6;
  cap.draws += size_t(room.meshes);
  cap.materials += size_t(room.meshes);
  out->capacity_ = cap;
  out->local_vertices_.reserve(cap.vertices);
  out->packed_indices_.reserve(cap.indices);
  out->packed_materials_.reserve(cap.materials);
  out->packed_ranges_.reserve(cap.draws);
  out->packed_range_materials_.reserve(cap.draws);
  out->virtual_objects.draws.reserve(cap.draws);
  out->local_lod_errors_.reserve(cap.draws);
  out->material_specular_kind.reserve(cap.materials);
  out->pack();

  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  auto vb = per_slot_buffer(graph, "virtual_objects_vertices", cap.vertices * sizeof(GpuVertex),
                            VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | storage);
  if (!vb) return vb.error();
  auto ib = per_slot_buffer(graph, "virtual_objects_indices", cap.indices * sizeof(uint32_t),
                            VK_BUFFER_USAGE_INDEX_BUFFER_BIT | storage);
  if (!ib) return ib.error();
  auto mb = per_slot_buffer(graph, "virtual_materials", cap.materials * sizeof(shader::GpuMaterial), storage);
  if (!mb) return mb.error();
  auto rb = per_slot_buffer(graph, "virtual_triangle_ranges", cap.draws * sizeof(glm::ivec4), storage);
  if (!rb) return rb.error();
  auto rmb = per_slot_buffer(graph, "virtual_triangle_range_materials", cap.draws * sizeof(int32_t), storage);
  if (!rmb) return rmb.error();
  out->virtual_objects.vertices = *vb;
  out->virtual_objects.indices = *ib;
  out->materials = *mb;
  out->triangles_.ranges = *rb;
  out->triangles_.materials = *rmb;
  out->slot_revision_.assign(graph.frames_in_flight(), ~uint64_t(0));
  out->slot_layout_.assign(graph.frames_in_flight(), ~uint64_t(0));
  out->bounds_revision_ = ~uint64_t(0);
  out->commit(graph);  // bounds now; each slot's copies are written the first time it is current

  ProxyData proxies;
  for (const RealGeometryDesc& proxy : scene.real_geometry) {
    auto model = load_gltf(proxy.gltf, proxy.placement);
    if (!model) return model.error();
    append_proxy(*model, proxies);
  }
  auto pset = upload_proxies(context, graph, proxies);
  if (!pset) return pset.error();
  out->real_proxies = std::move(*pset);

  // Texture array: one square side for all layers; the room's layers white until used.
  const size_t layer_bytes = size_t(out->texture_side_) * out->texture_side_ * 4;
  std::vector<uint8_t> texels(layer_bytes * layers, 255);
  for (size_t i = 0; i < textures.size(); ++i) {
    const ImageRGBA8& t = *textures[i];
    if (t.empty()) continue;
    if (!stbir_resize_uint8_srgb(t.data.data(), t.width, t.height, 0, texels.data() + layer_bytes * i,
                                 int(out->texture_side_), int(out->texture_side_), 0, 4, 3, 0))
      return fail(ErrorKind::Internal, "scene_gpu: resampling base-colour texture " + std::to_string(i) + " failed");
  }
  gpu::ImageCreateDesc desc;
  desc.format = VK_FORMAT_R8G8B8A8_SRGB;
  desc.width = desc.height = out->texture_side_;
  desc.layers = layers;
  desc.array_view = true;  // sampler2DArray, also with one layer
  desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  desc.name = "base_color_maps";
  auto image = context.create_image(desc);
  if (!image) return image.error();
  out->texture_array_ = *image;
  MRGI_TRY(context.upload_image(out->texture_array_, texels.data(), texels.size()));
  out->base_color_maps = graph.import_image("base_color_maps", out->texture_array_,
                                            VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, true);
  if (room.textures > 0) {
    auto staging = context.create_buffer(layer_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                         "object texture staging");
    if (!staging) return staging.error();
    out->texture_staging_ = *staging;
  }
  return out;
}

Status SceneGpu::upload_layers(const std::vector<const ImageRGBA8*>& textures, const std::vector<uint32_t>& layers) {
  for (size_t i = 0; i < textures.size(); ++i) {
    const ImageRGBA8& t = *textures[i];
    uint8_t* dst = static_cast<uint8_t*>(texture_staging_.mapped);
    const int side = int(texture_side_);
    if (t.empty()) {
      std::memset(dst, 255, size_t(side) * size_t(side) * 4);
    } else if (!stbir_resize_uint8_srgb(t.data.data(), t.width, t.height, 0, dst, side, side, 0, 4, 3, 0)) {
      return fail(ErrorKind::Internal, "scene_gpu: resampling an added object's texture " + std::to_string(i) + " failed");
    }
    MRGI_TRY(context_.upload_image_layer(texture_array_, layers[i], texture_staging_));
  }
  return ok_status();
}

Expected<size_t> SceneGpu::add_object(const Model& model, const Placement& placement, const std::string& what) {
  size_t slot = objects_.size();
  for (size_t i = 0; i < objects_.size() && slot == objects_.size(); ++i)
    if (!objects_[i].present) slot = i;
  const std::string where = what + ": ";
  if (slot == objects_.size())
    return fail(ErrorKind::BadUsage, where + "every object slot is taken (" + std::to_string(objects_.size()) + ": " +
                                         std::to_string(scene_objects_) + " of scene.json, " +
                                         std::to_string(objects_.size() - scene_objects_) +
                                         " of RuntimeSettings::objects.objects); remove an object first");
  MRGI_TRY(check_placement(slot, placement));
  for (size_t m = 0; m < model.materials.size(); ++m) {
    const Material& mat = model.materials[m];
    const std::string name = where + "material " + std::to_string(m) + " ";
    if (shader::specular_kind(mat.metallic, mat.roughness, mat.transmission) != shader::SPECULAR_NONE)
      return fail(ErrorKind::BadUsage, name + "is a mirror or glass (metallic " + std::to_string(mat.metallic) +
                                           ", roughness " + std::to_string(mat.roughness) + ", transmission " +
                                           std::to_string(mat.transmission) +
                                           "): such objects cannot be added at run time; declare them in scene.json "
                                           "and show or hide them");
    if (glossy_material(mat) && !glossy)
      return fail(ErrorKind::BadUsage, name + "is glossy (metallic " + std::to_string(mat.metallic) + ", roughness " +
                                           std::to_string(mat.roughness) +
                                           ") and the runtime was not prepared for glossy objects "
                                           "(RuntimeSettings::objects.glossy)");
    if (emissive_material(mat) && !emissive)
      return fail(ErrorKind::BadUsage, name + "emits light and the runtime was not prepared for emissive objects "
                                           "(RuntimeSettings::objects.emissive)");
  }
  ObjectMeshes meshes = object_meshes(model);
  const Totals need = totals(&meshes);
  // `free`: what the room has left of it with every present object in.
  auto full = [&](const char* field, size_t has, size_t free) {
    return fail(ErrorKind::BadUsage, where + "the object needs " + std::to_string(has) + " " + field + ", " +
                                         std::to_string(free) + " are free (RuntimeSettings::objects." + field + ")");
  };
  const Totals used = totals(nullptr);
  if (need.vertices > capacity_.vertices)
    return full("vertices", meshes.vertices.size(), capacity_.vertices - used.vertices);
  if (need.triangles > capacity_.triangles)
    return full("triangles", meshes.triangles, capacity_.triangles - used.triangles);
  // The levels of detail take at most as many indices again as the triangles' own (the room
  // reserves that); a mesh whose simplification keeps more is told in the same unit.
  if (need.indices > capacity_.indices)
    return full("triangles (with their levels of detail)", meshes.indices.size() / 3,
                (capacity_.indices - used.indices) / 3);
  if (need.draws > capacity_.draws) return full("meshes", meshes.draws.size(), capacity_.draws - used.draws);
  if (need.materials > capacity_.materials)
    return fail(ErrorKind::BadUsage, where + "the object has " + std::to_string(meshes.materials.size()) +
                                         " materials, " + std::to_string(capacity_.materials - used.materials) +
                                         " are free (one a mesh: RuntimeSettings::objects.meshes)");
  if (meshes.textures.size() > free_layers_.size()) return full("textures", meshes.textures.size(), free_layers_.size());
  std::vector<uint32_t> layers(free_layers_.end() - std::ptrdiff_t(meshes.textures.size()), free_layers_.end());
  std::reverse(layers.begin(), layers.end());
  MRGI_TRY(upload_layers(meshes.textures, layers));
  free_layers_.resize(free_layers_.size() - layers.size());
  meshes.textures.clear();
  ObjectSpan& span = objects_[slot];
  span = ObjectSpan{};
  span.meshes = std::move(meshes);
  span.layers = std::move(layers);
  set_materials(span, span.layers);
  span.placement = placement;
  span.present = span.visible = true;
  ++visible_count_;
  pack();
  return slot;
}

Status SceneGpu::remove_object(size_t object) {
  if (!present(object))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) +
                                         (object < objects_.size() ? ": the slot is empty"
                                                                   : ": the scene has " + std::to_string(objects_.size()) +
                                                                         " slots (indices from 0)"));
  ObjectSpan& o = objects_[object];
  free_layers_.insert(free_layers_.end(), o.layers.rbegin(), o.layers.rend());
  if (o.visible) --visible_count_;
  o = ObjectSpan{};
  o.visible = false;
  pack();
  return ok_status();
}

Status SceneGpu::set_placement(size_t object, const Placement& p) {
  if (!present(object))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) +
                                         (object < objects_.size() ? ": the slot is empty"
                                                                   : ": the scene has " + std::to_string(objects_.size()) +
                                                                         " (indices from 0)"));
  MRGI_TRY(check_placement(object, p));
  Placement& cur = objects_[object].placement;
  if (cur.position == p.position && cur.rotation == p.rotation && cur.scale == p.scale) return ok_status();
  cur = p;
  ++revision_;
  return ok_status();
}

Status SceneGpu::set_visible(size_t object, bool visible) {
  if (!present(object))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) +
                                         (object < objects_.size() ? ": the slot is empty"
                                                                   : ": the scene has " + std::to_string(objects_.size()) +
                                                                         " (indices from 0)"));
  if (objects_[object].visible == visible) return ok_status();
  objects_[object].visible = visible;
  visible_count_ = visible ? visible_count_ + 1 : visible_count_ - 1;
  ++revision_;
  return ok_status();
}

void SceneGpu::write_vertices(GpuVertex* out) const {
  for (const ObjectSpan& o : objects_) {
    if (!o.present) continue;
    if (!o.visible) {
      for (uint32_t i = o.first_vertex; i < o.first_vertex + o.vertex_count; ++i)
        out[i] = GpuVertex{glm::vec3(0.0f, -kHiddenDepth_m, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec2(0.0f)};
      continue;
    }
    const glm::mat4 m = o.placement.matrix();
    const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(m)));
    for (uint32_t i = o.first_vertex; i < o.first_vertex + o.vertex_count; ++i) {
      const GpuVertex& v = local_vertices_[i];
      GpuVertex w;
      w.position = glm::vec3(m * glm::vec4(v.position, 1.0f));
      const glm::vec3 n = nm * v.normal;
      const float len = glm::length(n);
      w.normal = len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
      w.uv = v.uv;
      out[i] = w;
    }
  }
}

void SceneGpu::update_bounds() {
  MeshSet& set = virtual_objects;
  const glm::vec3 old_min = set.bounds_min, old_max = set.bounds_max;
  set.bounds_min = glm::vec3(1e30f);
  set.bounds_max = glm::vec3(-1e30f);
  for (const ObjectSpan& o : objects_) {
    if (!o.present) continue;
    if (!o.visible) {
      for (size_t d = o.first_draw; d < o.first_draw + o.draw_count; ++d)
        set.draws[d].bounds_min = set.draws[d].bounds_max = glm::vec3(0.0f, -kHiddenDepth_m, 0.0f);
      continue;
    }
    const glm::mat4 m = o.placement.matrix();
    const float grow = std::max({o.placement.scale.x, o.placement.scale.y, o.placement.scale.z});
    for (size_t d = o.first_draw; d < o.first_draw + o.draw_count; ++d) {
      DrawRange& range = set.draws[d];
      range.bounds_min = glm::vec3(1e30f);
      range.bounds_max = glm::vec3(-1e30f);
      // The range's vertices (the index list's vertices are a subset of the object's span).
      const uint32_t first = uint32_t(range.vertex_offset);
      const uint32_t end = d + 1 < o.first_draw + o.draw_count ? uint32_t(set.draws[d + 1].vertex_offset)
                                                               : o.first_vertex + o.vertex_count;
      for (uint32_t i = first; i < end; ++i) {
        const glm::vec3 p = glm::vec3(m * glm::vec4(local_vertices_[i].position, 1.0f));
        range.bounds_min = glm::min(range.bounds_min, p);
        range.bounds_max = glm::max(range.bounds_max, p);
      }
      for (size_t l = 0; l < range.lods.size(); ++l) range.lods[l].error_m = local_lod_errors_[d][l] * grow;
      set.bounds_min = glm::min(set.bounds_min, range.bounds_min);
      set.bounds_max = glm::max(set.bounds_max, range.bounds_max);
    }
  }
  if (visible_count_ == 0) {  // nothing shown: the last bounds stay (nothing is drawn by them)
    set.bounds_min = old_min;
    set.bounds_max = old_max;
  }
}

void SceneGpu::commit(gpu::FrameGraph& graph) {
  if (objects_.empty()) return;
  if (bounds_revision_ != revision_) {
    update_bounds();
    bounds_revision_ = revision_;
  }
  const uint32_t slot = graph.slot();
  if (slot >= slot_revision_.size()) return;
  if (slot_revision_[slot] != revision_) {
    write_vertices(static_cast<GpuVertex*>(graph.mapped(virtual_objects.vertices, slot)));
    slot_revision_[slot] = revision_;
  }
  if (slot_layout_[slot] != layout_revision_) {
    auto copy = [&](gpu::BufferHandle h, const auto& list) {
      if (!list.empty()) std::memcpy(graph.mapped(h, slot), list.data(), list.size() * sizeof(list[0]));
    };
    copy(virtual_objects.indices, packed_indices_);
    copy(materials, packed_materials_);
    copy(triangles_.ranges, packed_ranges_);
    copy(triangles_.materials, packed_range_materials_);
    if (packed_ranges_.empty()) {  // the shaders' arrays hold at least one entry
      std::memset(graph.mapped(triangles_.ranges, slot), 0, sizeof(glm::ivec4));
      std::memset(graph.mapped(triangles_.materials, slot), 0, sizeof(int32_t));
    }
    slot_layout_[slot] = layout_revision_;
  }
}

SceneGpu::~SceneGpu() {
  context_.destroy(texture_staging_);
  context_.destroy(texture_array_);
}

int SceneGpu::object_specular_kinds(size_t object) const {
  int kinds = 0;
  const ObjectSpan& o = objects_[object];
  for (size_t d = o.first_draw; d < o.first_draw + o.draw_count; ++d) {
    const int m = virtual_objects.draws[d].material;
    const int kind = m >= 0 && size_t(m) < material_specular_kind.size() ? material_specular_kind[size_t(m)] : 0;
    if (kind != 0) kinds |= 1 << kind;
  }
  return kinds;
}

}  // namespace mrgi::frame
