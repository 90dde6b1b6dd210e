// One virtual object's meshes as loaded (model space), before SceneGpu packs them with the
// others: draw ranges with their levels of detail, sphere proxies for occlusion, the surface by
// orientation and the mean albedo. Host work only, done at start-up for scene.json's objects and
// in SceneGpu::add_object for an app's.
#include <algorithm>
#include <cmath>

#include <meshoptimizer.h>

#include "frame/occluder_spheres.h"
#include "frame/scene_gpu.h"
#include "mrgi/metrics.h"

namespace mrgi::frame {
namespace {

// Levels of detail per virtual primitive: each halves the previous one's triangle count
// (simplified from the original, not from the previous level), down to kMinLodTriangles, and
// stops where meshoptimizer cannot reach 80 % of the previous count (the mesh is as coarse as
// its topology allows) or the error would exceed kMaxLodRelativeError of the mesh's extent.
constexpr int kMaxLods = 6;
constexpr size_t kMinLodTriangles = 64;
constexpr float kMaxLodRelativeError = 0.05f;

// Appends the primitive's levels of detail after its own indices (at range.first_index) to
// `indices`, with their errors in model-space metres.
void append_lods(const MeshPrimitive& prim, DrawRange& range, std::vector<uint32_t>& indices,
                 std::vector<float>& errors) {
  range.lods.push_back({range.first_index, range.index_count, 0.0f});
  errors.push_back(0.0f);
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
    errors.push_back(error * scale);
    indices.insert(indices.end(), lod.begin(), lod.begin() + std::ptrdiff_t(m));
    previous = m;
  }
}

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

}  // namespace

DrawRange append_primitive(const MeshPrimitive& prim, std::vector<GpuVertex>& vertices, std::vector<uint32_t>& indices) {
  DrawRange range;
  range.first_index = uint32_t(indices.size());
  range.index_count = uint32_t(prim.indices.size());
  range.vertex_offset = int32_t(vertices.size());
  range.bounds_min = glm::vec3(1e30f);
  range.bounds_max = glm::vec3(-1e30f);
  for (size_t i = 0; i < prim.positions.size(); ++i) {
    GpuVertex v;
    v.position = prim.positions[i];
    v.normal = i < prim.normals.size() ? prim.normals[i] : glm::vec3(0.0f, 1.0f, 0.0f);
    v.uv = i < prim.uvs.size() ? prim.uvs[i] : glm::vec2(0.0f);
    range.bounds_min = glm::min(range.bounds_min, v.position);
    range.bounds_max = glm::max(range.bounds_max, v.position);
    vertices.push_back(v);
  }
  indices.insert(indices.end(), prim.indices.begin(), prim.indices.end());
  return range;
}

ObjectMeshes object_meshes(const Model& model) {
  ObjectMeshes out;
  out.materials = model.materials;
  for (const Texture& t : model.textures) out.textures.push_back(&t.image);
  for (const MeshPrimitive& prim : model.primitives) {
    if (prim.indices.empty() || prim.positions.empty()) continue;
    DrawRange range = append_primitive(prim, out.vertices, out.indices);
    range.material = prim.material >= 0 && size_t(prim.material) < model.materials.size() ? prim.material : -1;
    range.double_sided = range.material >= 0 && model.materials[size_t(range.material)].double_sided;
    out.triangles += uint32_t(prim.indices.size() / 3);
    std::vector<float> errors;
    append_lods(prim, range, out.indices, errors);
    out.lod_errors.push_back(std::move(errors));
    out.draws.push_back(range);
  }
  const ObjectMesh mesh = object_mesh(model);
  OccluderFitSettings fit;
  fit.max_spheres = SceneGpu::kOccluderSpheres;
  out.occluders = fit_occluder_spheres(mesh.positions, mesh.indices, fit);
  out.albedo = mean_albedo(mesh);
  out.patches = cluster_surface_orientations(mesh.positions, mesh.indices, mesh.triangle_albedo,
                                             SceneGpu::kOrientedPatches);
  return out;
}

}  // namespace mrgi::frame
