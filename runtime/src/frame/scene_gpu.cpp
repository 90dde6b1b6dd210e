#include "frame/scene_gpu.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <meshoptimizer.h>

#define STB_IMAGE_RESIZE_STATIC
#define STB_IMAGE_RESIZE_IMPLEMENTATION
#include <stb/stb_image_resize.h>

#include "common/scene_materials.glsl"
#include "frame/occluder_spheres.h"
#include "shared/specular_math.h"
#include "gpu/vk_check.h"
#include "mrgi/metrics.h"

namespace mrgi::frame {
namespace {

struct MeshData {
  std::vector<GpuVertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<DrawRange> draws;
  glm::vec3 lo{1e30f}, hi{-1e30f};
};

// Levels of detail per virtual primitive: each halves the previous one's triangle count
// (simplified from the original, not from the previous level), down to kMinLodTriangles, and
// stops where meshoptimizer cannot reach 80 % of the previous count (the mesh is as coarse as
// its topology allows) or the error would exceed kMaxLodRelativeError of the mesh's extent.
constexpr int kMaxLods = 6;
constexpr size_t kMinLodTriangles = 64;
constexpr float kMaxLodRelativeError = 0.05f;

void append_lods(const MeshPrimitive& prim, DrawRange& range, std::vector<uint32_t>& indices) {
  range.lods.push_back({range.first_index, range.index_count, 0.0f});
  const size_t n = prim.indices.size();
  const float* positions = &prim.positions[0].x;
  const float scale = meshopt_simplifyScale(positions, prim.positions.size(), sizeof(glm::vec3));
  std::vector<uint32_t> lod(n);
  size_t previous = n;
  for (int k = 1; k < kMaxLods; ++k) {
    const size_t target = previous / 6 * 3;  // half the triangles
    if (target < 3 * kMinLodTriangles) break;
    float error = 0.0f;
    const size_t m = meshopt_simplify(lod.data(), prim.indices.data(), n, positions,
                                      prim.positions.size(), sizeof(glm::vec3), target,
                                      kMaxLodRelativeError, 0, &error);
    if (m < 3 || m > previous * 8 / 10) break;
    range.lods.push_back({uint32_t(indices.size()), uint32_t(m), error * scale});
    indices.insert(indices.end(), lod.begin(), lod.begin() + std::ptrdiff_t(m));
    previous = m;
  }
}

// Appends a model's primitives; material indices are offset by `material_base`. With `lods`,
// each primitive also gets its levels of detail (append_lods).
void append_model(const Model& model, int material_base, MeshData& out, bool lods) {
  for (const MeshPrimitive& prim : model.primitives) {
    if (prim.indices.empty() || prim.positions.empty()) continue;
    DrawRange range;
    range.first_index = uint32_t(out.indices.size());
    range.index_count = uint32_t(prim.indices.size());
    range.vertex_offset = int32_t(out.vertices.size());
    range.material = prim.material < 0 ? 0 : material_base + prim.material;
    range.double_sided = prim.material >= 0 && size_t(prim.material) < model.materials.size() &&
                         model.materials[size_t(prim.material)].double_sided;
    range.bounds_min = glm::vec3(1e30f);
    range.bounds_max = glm::vec3(-1e30f);
    for (size_t i = 0; i < prim.positions.size(); ++i) {
      GpuVertex v;
      v.position = prim.positions[i];
      v.normal = i < prim.normals.size() ? prim.normals[i] : glm::vec3(0.0f, 1.0f, 0.0f);
      v.uv = i < prim.uvs.size() ? prim.uvs[i] : glm::vec2(0.0f);
      out.lo = glm::min(out.lo, v.position);
      out.hi = glm::max(out.hi, v.position);
      range.bounds_min = glm::min(range.bounds_min, v.position);
      range.bounds_max = glm::max(range.bounds_max, v.position);
      out.vertices.push_back(v);
    }
    out.indices.insert(out.indices.end(), prim.indices.begin(), prim.indices.end());
    if (lods) append_lods(prim, range, out.indices);
    out.draws.push_back(range);
  }
}

// `per_slot_vertices`: the vertex buffer host-visible with a copy per frame slot, written by
// the caller (the moving virtual objects); else device-local and uploaded here.
Expected<MeshSet> upload_meshes(gpu::Context& ctx, gpu::FrameGraph& graph, const MeshData& data,
                                const std::string& name, bool per_slot_vertices) {
  MeshSet set;
  // Never zero-sized (Vulkan forbids it); an empty set simply has no draws.
  const VkDeviceSize vbytes = std::max<VkDeviceSize>(64, data.vertices.size() * sizeof(GpuVertex));
  const VkDeviceSize ibytes = std::max<VkDeviceSize>(64, data.indices.size() * sizeof(uint32_t));
  // Storage too: compute passes read the meshes as lists (gi/ism.h samples points on them).
  gpu::BufferDesc vdesc{name + "_vertices", vbytes};
  if (per_slot_vertices) {
    vdesc.memory = gpu::MemoryUsage::Upload;
    vdesc.per_frame_copies = true;
  }
  auto vb = graph.create_buffer(vdesc, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                                              VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!vb) return vb.error();
  auto ib = graph.create_buffer({name + "_indices", ibytes}, VK_BUFFER_USAGE_INDEX_BUFFER_BIT |
                                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!ib) return ib.error();
  if (!data.vertices.empty()) {
    if (!per_slot_vertices)
      MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(*vb, 0), data.vertices.data(),
                                 data.vertices.size() * sizeof(GpuVertex)));
    MRGI_TRY(ctx.upload_buffer(graph.gpu_buffer(*ib, 0), data.indices.data(),
                               data.indices.size() * sizeof(uint32_t)));
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

namespace {

// A primitive's diffuse albedo (linear RGB): its base colour factor times its texture's mean;
// metals reflect little diffusely.
glm::dvec3 primitive_albedo(const Model& model, const MeshPrimitive& prim) {
  glm::dvec3 albedo(1.0);
  float metallic = 1.0f;
  if (prim.material >= 0 && size_t(prim.material) < model.materials.size()) {
    const Material& mat = model.materials[size_t(prim.material)];
    albedo = glm::dvec3(glm::vec3(mat.base_color_factor));
    metallic = mat.metallic;
    if (mat.base_color_texture >= 0 && size_t(mat.base_color_texture) < model.textures.size()) {
      const ImageRGBA8& img = model.textures[size_t(mat.base_color_texture)].image;
      glm::dvec3 t(0.0);
      size_t n = 0;
      for (size_t i = 0; i < img.pixel_count(); i += 7, ++n)
        t += glm::dvec3(srgb8_to_linear(img.data[i * 4]), srgb8_to_linear(img.data[i * 4 + 1]),
                        srgb8_to_linear(img.data[i * 4 + 2]));
      if (n) albedo *= t / double(n);
    }
  }
  return albedo * double(1.0f - std::clamp(metallic, 0.0f, 1.0f));
}

// The object's primitives as one mesh (model space) with each triangle's primitive albedo.
struct ObjectMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<glm::vec3> triangle_albedo;
};
ObjectMesh object_mesh(const Model& model) {
  ObjectMesh m;
  for (const MeshPrimitive& prim : model.primitives) {
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), prim.positions.begin(), prim.positions.end());
    const glm::vec3 albedo(primitive_albedo(model, prim));
    for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
      for (int k = 0; k < 3; ++k) m.indices.push_back(base + prim.indices[t + size_t(k)]);
      m.triangle_albedo.push_back(albedo);
    }
  }
  return m;
}

// The object's mean diffuse albedo (linear RGB), weighted by the triangles' surface area.
glm::vec3 mean_albedo(const ObjectMesh& mesh) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
    if (i0 >= mesh.positions.size() || i1 >= mesh.positions.size() || i2 >= mesh.positions.size()) continue;
    const glm::vec3 p0 = mesh.positions[i0];
    const double a = 0.5 * double(glm::length(glm::cross(mesh.positions[i1] - p0, mesh.positions[i2] - p0)));
    sum += a * glm::dvec3(mesh.triangle_albedo[t / 3]);
    area += a;
  }
  return area > 0.0 && std::isfinite(area) ? glm::vec3(sum / area) : glm::vec3(0.0f);
}

// The object's mesh fitted with sphere proxies (model space).
std::vector<glm::vec4> fit_model_occluders(const ObjectMesh& mesh) {
  OccluderFitSettings fit;
  fit.max_spheres = SceneGpu::kOccluderSpheres;
  return fit_occluder_spheres(mesh.positions, mesh.indices, fit);
}

}  // namespace

void SceneGpu::occluder_spheres(int per_object, std::vector<glm::vec4>& out, std::vector<glm::vec4>* albedo,
                                std::vector<int>* object) const {
  int ordinal = 0;
  for (const ObjectSpan& o : objects_) {
    if (!o.visible) continue;
    const int this_object = ordinal++;
    const glm::mat4 m = o.placement.matrix();
    const float grow = std::max({o.placement.scale.x, o.placement.scale.y, o.placement.scale.z});
    const size_t n = std::min(o.occluders.size(), size_t(std::max(per_object, 0)));
    for (size_t k = 0; k < n; ++k) {
      out.emplace_back(glm::vec3(m * glm::vec4(glm::vec3(o.occluders[k]), 1.0f)), o.occluders[k].w * grow);
      if (albedo) albedo->emplace_back(o.albedo, 0.0f);
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
    const int n = int(std::min(o.patches.size(), size_t(kOrientedPatches)));
    for (int k = 0; k < n; ++k) {
      out[k] = o.patches[size_t(k)];
      const glm::vec3 w = normals * o.patches[size_t(k)].normal;
      out[k].normal = glm::length(w) > 0.0f ? glm::normalize(w) : o.patches[size_t(k)].normal;
      const float to_world = std::isfinite(det) ? det * glm::length(w) : 0.0f;
      out[k].area = o.patches[size_t(k)].area * to_world;
      out[k].facing_area = o.patches[size_t(k)].facing_area * to_world;
    }
    return n;
  }
  return 0;
}

Expected<std::unique_ptr<SceneGpu>> SceneGpu::create(gpu::Context& context, gpu::FrameGraph& graph,
                                                     const SceneDesc& scene) {
  std::unique_ptr<SceneGpu> out(new SceneGpu(context));
  MeshData virtual_data, proxy_data;
  std::vector<shader::GpuMaterial> materials;
  std::vector<const ImageRGBA8*> textures;
  std::vector<Model> models;  // kept until the textures are resampled
  models.reserve(scene.virtual_objects.size());
  for (const VirtualObjectDesc& obj : scene.virtual_objects) {
    // Model space (the placement is applied per frame, commit()); checked like set_placement.
    auto model = load_gltf(obj.gltf, Placement{});
    if (!model) return model.error();
    models.push_back(std::move(*model));
  }
  // Material 0 is the glTF default material (white, metallic 1, roughness 1 per the spec).
  materials.push_back({glm::vec4(1.0f), glm::vec4(1.0f, 1.0f, -1.0f, 0.0f), glm::vec4(0.0f),
                       glm::vec4(0.0f, 1.5f, 0.0f, 0.0f), glm::vec4(1.0f)});
  out->material_specular_kind.push_back(0);
  for (const Model& m : models) {
    const int material_base = int(materials.size());
    const int texture_base = int(textures.size());
    for (const Material& mat : m.materials) {
      const float layer = mat.base_color_texture >= 0 &&
                                  mat.base_color_texture < int(m.textures.size())
                              ? float(texture_base + mat.base_color_texture)
                              : -1.0f;
      const float emissive_layer = mat.emissive_texture >= 0 &&
                                           mat.emissive_texture < int(m.textures.size())
                                       ? float(texture_base + mat.emissive_texture)
                                       : -1.0f;
      const int kind = shader::specular_kind(mat.metallic, mat.roughness, mat.transmission);
      materials.push_back({mat.base_color_factor,
                           glm::vec4(mat.metallic, mat.roughness, layer, 0.0f),
                           glm::vec4(glm::max(mat.emissive, glm::vec3(0.0f)), emissive_layer),
                           glm::vec4(float(kind), mat.ior, mat.attenuation_distance, mat.transmission),
                           glm::vec4(mat.attenuation_color, 0.0f)});
      out->specular = out->specular || kind != shader::SPECULAR_NONE;
      out->material_specular_kind.push_back(kind);
      const glm::vec3 e = materials.back().emission;
      out->emissive = out->emissive || e.x > 0.0f || e.y > 0.0f || e.z > 0.0f;
      out->glossy = out->glossy || mat.metallic > kGlossyMetallic || mat.roughness < kGlossyRoughness;
    }
    for (const Texture& t : m.textures) textures.push_back(&t.image);
    ObjectSpan span;
    span.first_vertex = uint32_t(virtual_data.vertices.size());
    span.first_draw = virtual_data.draws.size();
    append_model(m, material_base, virtual_data, true);
    span.vertex_count = uint32_t(virtual_data.vertices.size()) - span.first_vertex;
    span.draw_count = virtual_data.draws.size() - span.first_draw;
    span.placement = scene.virtual_objects[out->objects_.size()].placement;
    const ObjectMesh mesh = object_mesh(m);
    span.occluders = fit_model_occluders(mesh);
    span.albedo = mean_albedo(mesh);
    span.patches = cluster_surface_orientations(mesh.positions, mesh.indices, mesh.triangle_albedo, kOrientedPatches);
    out->objects_.push_back(span);
  }
  for (const DrawRange& d : virtual_data.draws) {
    std::vector<float> errors;
    for (const DrawRange::Lod& l : d.lods) errors.push_back(l.error_m);
    out->local_lod_errors_.push_back(std::move(errors));
  }
  out->local_vertices_ = virtual_data.vertices;
  for (const RealGeometryDesc& proxy : scene.real_geometry) {
    auto model = load_gltf(proxy.gltf, proxy.placement);
    if (!model) return model.error();
    append_model(*model, 0, proxy_data, false);
  }

  for (size_t i = 0; i < out->objects_.size(); ++i)
    MRGI_TRY(out->set_placement(i, out->objects_[i].placement));  // refuses a bad scene.json pose
  out->visible_count_ = out->objects_.size();
  auto vset = upload_meshes(context, graph, virtual_data, "virtual_objects", true);
  if (!vset) return vset.error();
  out->virtual_objects = std::move(*vset);
  out->slot_revision_.assign(graph.frames_in_flight(), ~uint64_t(0));
  out->revision_ = 0;
  out->bounds_revision_ = ~uint64_t(0);
  out->commit(graph);  // bounds now; each slot's copy is written the first time it is current
  auto pset = upload_meshes(context, graph, proxy_data, "real_proxies", false);
  if (!pset) return pset.error();
  out->real_proxies = std::move(*pset);

  auto mb = graph.create_buffer({"virtual_materials", materials.size() * sizeof(shader::GpuMaterial)},
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!mb) return mb.error();
  MRGI_TRY(context.upload_buffer(graph.gpu_buffer(*mb, 0), materials.data(),
                                 materials.size() * sizeof(shader::GpuMaterial)));
  out->materials = *mb;

  // Texture array: one square side for all layers.
  uint32_t side = 1;
  for (const ImageRGBA8* t : textures)
    side = std::max<uint32_t>(side, uint32_t(std::max(t->width, t->height)));
  side = std::min<uint32_t>(side, kMaxTextureSide);
  const uint32_t layers = std::max<uint32_t>(1, uint32_t(textures.size()));
  std::vector<uint8_t> texels(size_t(side) * side * 4 * layers, 255);
  for (size_t i = 0; i < textures.size(); ++i) {
    const ImageRGBA8& t = *textures[i];
    if (t.empty()) continue;
    uint8_t* dst = texels.data() + size_t(side) * side * 4 * i;
    if (!stbir_resize_uint8_srgb(t.data.data(), t.width, t.height, 0, dst, int(side), int(side), 0,
                                 4, 3, 0))
      return fail(ErrorKind::Internal, "scene_gpu: resampling base-colour texture " +
                                           std::to_string(i) + " failed");
  }
  gpu::ImageCreateDesc desc;
  desc.format = VK_FORMAT_R8G8B8A8_SRGB;
  desc.width = desc.height = side;
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
  return out;
}

Status SceneGpu::set_placement(size_t object, const Placement& p) {
  if (object >= objects_.size())
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) + ": the scene has " +
                                         std::to_string(objects_.size()) + " (indices from 0)");
  const glm::vec4 q(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w);
  bool finite = true;
  for (int i = 0; i < 3; ++i) finite = finite && std::isfinite(p.position[i]) && std::isfinite(p.scale[i]);
  for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(q[i]);
  if (!finite || !(glm::length(q) > 1e-6f))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) +
                                         ": placement must be finite with a non-zero rotation quaternion");
  if (!(p.scale.x > 0.0f && p.scale.y > 0.0f && p.scale.z > 0.0f))
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) + ": scale must be positive");
  Placement& cur = objects_[object].placement;
  if (cur.position == p.position && cur.rotation == p.rotation && cur.scale == p.scale) return ok_status();
  cur = p;
  ++revision_;
  return ok_status();
}

Status SceneGpu::set_visible(size_t object, bool visible) {
  if (object >= objects_.size())
    return fail(ErrorKind::BadUsage, "virtual object " + std::to_string(object) + ": the scene has " +
                                         std::to_string(objects_.size()) + " (indices from 0)");
  if (objects_[object].visible == visible) return ok_status();
  objects_[object].visible = visible;
  visible_count_ = visible ? visible_count_ + 1 : visible_count_ - 1;
  ++revision_;
  return ok_status();
}

void SceneGpu::write_vertices(GpuVertex* out) const {
  for (const ObjectSpan& o : objects_) {
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
  if (slot >= slot_revision_.size() || slot_revision_[slot] == revision_) return;
  write_vertices(static_cast<GpuVertex*>(graph.mapped(virtual_objects.vertices, slot)));
  slot_revision_[slot] = revision_;
}

SceneGpu::~SceneGpu() {
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
