// glTF 2.0 (.gltf / .glb) through Debian's shared libtinygltf (the library provides
// TINYGLTF_IMPLEMENTATION and decodes embedded images with stb). The default scene's node tree is
// flattened into world-space triangle lists with the placement applied on top.
//
// Rules beyond tinygltf's own checks:
//   - primitives must be triangle lists (mode 4); other modes are refused naming the mesh;
//   - every accessor read is bounds-checked against its buffer, indices against the vertex count;
//   - missing normals are generated flat, as the glTF spec requires ("client implementations
//     MUST calculate flat normals"): such primitives are de-indexed, three vertices per triangle;
//   - sparse accessors are NotImplemented (none of the project's assets use them).
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "mrgi/scene.h"
#include "scene/gltf_input.h"

namespace mrgi {
namespace {

constexpr int kMaxNodeDepth = 256;  // guards against cyclic node graphs in broken files

struct LoadContext {
  const std::string& path;
  const tinygltf::Model& gltf;
  Model* out;
  std::map<int, int> texture_of_gltf_texture;
  size_t node_visits = 0, vertices = 0;  // against gltf::kMaxNodeVisits / kMaxVertices
};

std::string mesh_label(const tinygltf::Model& m, int mesh, size_t primitive) {
  const std::string& name = m.meshes[size_t(mesh)].name;
  return "mesh " + std::to_string(mesh) + (name.empty() ? "" : " '" + name + "'") + " primitive " +
         std::to_string(primitive);
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "points";
    case TINYGLTF_MODE_LINE: return "lines";
    case TINYGLTF_MODE_LINE_LOOP: return "line loop";
    case TINYGLTF_MODE_LINE_STRIP: return "line strip";
    case TINYGLTF_MODE_TRIANGLE_STRIP: return "triangle strip";
    case TINYGLTF_MODE_TRIANGLE_FAN: return "triangle fan";
  }
  return "unknown";
}

// Component value as float, with glTF's normalisation rules for integer types.
float read_component(const uint8_t* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const float v = float(int8_t(*p));
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return float(v); }
  }
  return 0.0f;
}

// Locates an accessor's bytes: first element pointer and stride, after checking the range fits.
struct AccessorView {
  const uint8_t* data = nullptr;  // nullptr: no buffer view, all elements zero (glTF rule)
  size_t stride = 0;
  size_t count = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
};

Expected<AccessorView> view_accessor(const LoadContext& ctx, int index, const std::string& what) {
  const auto& m = ctx.gltf;
  if (index < 0 || size_t(index) >= m.accessors.size())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": accessor " + std::to_string(index) +
                                         " does not exist");
  const auto& acc = m.accessors[size_t(index)];
  if (acc.sparse.isSparse)
    return fail(ErrorKind::NotImplemented, ctx.path + ": " + what + ": sparse accessor " +
                                               std::to_string(index) + " is not supported");
  AccessorView v;
  v.count = acc.count;
  v.component_type = acc.componentType;
  v.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
  v.normalized = acc.normalized;
  const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
  if (v.components <= 0 || comp_size <= 0)
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": accessor " + std::to_string(index) +
                                         " has an invalid type or component type");
  if (acc.bufferView < 0) return v;
  if (size_t(acc.bufferView) >= m.bufferViews.size())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": buffer view " +
                                         std::to_string(acc.bufferView) + " does not exist");
  const auto& bv = m.bufferViews[size_t(acc.bufferView)];
  if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": buffer " + std::to_string(bv.buffer) +
                                         " does not exist");
  const auto& buf = m.buffers[size_t(bv.buffer)].data;
  const size_t elem = size_t(comp_size) * size_t(v.components);
  v.stride = bv.byteStride ? bv.byteStride : elem;
  const size_t start = bv.byteOffset + acc.byteOffset;
  const size_t span = v.count == 0 ? 0 : v.stride * (v.count - 1) + elem;
  if (start + span > bv.byteOffset + bv.byteLength || bv.byteOffset + bv.byteLength > buf.size())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": accessor " + std::to_string(index) +
                                         " reads past the end of its buffer view or buffer");
  v.data = buf.data() + start;
  return v;
}

template <int N>
Expected<std::vector<glm::vec<N, float>>> read_vectors(const LoadContext& ctx, int index,
                                                       const std::string& what) {
  auto v = view_accessor(ctx, index, what);
  if (!v) return v.error();
  if (v->components != N)
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": accessor " + std::to_string(index) +
                                         " has " + std::to_string(v->components) +
                                         " components, expected " + std::to_string(N));
  const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(v->component_type));
  std::vector<glm::vec<N, float>> out(v->count, glm::vec<N, float>(0.0f));
  if (!v->data) return out;
  for (size_t i = 0; i < v->count; ++i) {
    const uint8_t* p = v->data + i * v->stride;
    for (int c = 0; c < N; ++c) {
      const float f = read_component(p + size_t(c) * size_t(comp_size), v->component_type, v->normalized);
      if (!std::isfinite(f))
        return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": accessor " + std::to_string(index) +
                                             " element " + std::to_string(i) + " is not finite");
      out[i][c] = f;
    }
  }
  return out;
}

Expected<std::vector<uint32_t>> read_indices(const LoadContext& ctx, int index, size_t vertex_count,
                                             const std::string& what) {
  std::vector<uint32_t> out;
  if (index < 0) {  // non-indexed: vertices in order
    out.resize(vertex_count);
    for (size_t i = 0; i < vertex_count; ++i) out[i] = uint32_t(i);
    return out;
  }
  auto v = view_accessor(ctx, index, what + " indices");
  if (!v) return v.error();
  const int t = v->component_type;
  if (v->components != 1 || (t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                             t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                             t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": indices must be scalar u8, u16 or u32");
  out.resize(v->count, 0);
  if (!v->data) return out;
  for (size_t i = 0; i < v->count; ++i) {
    const uint8_t* p = v->data + i * v->stride;
    uint32_t idx = 0;
    if (t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) idx = *p;
    else if (t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) { uint16_t s; std::memcpy(&s, p, 2); idx = s; }
    else std::memcpy(&idx, p, 4);
    if (idx >= vertex_count)
      return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": index " + std::to_string(idx) +
                                           " at position " + std::to_string(i) + " is out of range (" +
                                           std::to_string(vertex_count) + " vertices)");
    out[i] = idx;
  }
  return out;
}

// Any decoded glTF image (1-4 channels, 8 or 16 bits) to sRGB-encoded RGBA8.
Expected<ImageRGBA8> to_rgba8(const LoadContext& ctx, const tinygltf::Image& img, int image_index) {
  const int n = img.component, bytes = img.bits / 8;
  // tinygltf leaves an image it could not read empty (with only a warning): name its file.
  if (img.image.empty() && !img.uri.empty() && img.uri.rfind("data:", 0) != 0)
    return fail(ErrorKind::BadInput, ctx.path + ": image " + std::to_string(image_index) + " ('" +
                                         img.uri + "', images[" + std::to_string(image_index) +
                                         "].uri): the file is missing or unreadable (looked for "
                                         "next to the model, inside its folder)");
  if (img.width <= 0 || img.height <= 0 || n < 1 || n > 4 || (bytes != 1 && bytes != 2) ||
      img.image.size() != size_t(img.width) * size_t(img.height) * size_t(n) * size_t(bytes))
    return fail(ErrorKind::BadInput, ctx.path + ": image " + std::to_string(image_index) +
                                         " could not be decoded (" + std::to_string(img.width) + "x" +
                                         std::to_string(img.height) + ", " + std::to_string(n) +
                                         " channels, " + std::to_string(img.bits) + " bits)");
  ImageRGBA8 out(img.width, img.height, 255);
  for (size_t p = 0; p < out.pixel_count(); ++p) {
    uint8_t ch[4] = {0, 0, 0, 255};
    for (int c = 0; c < n; ++c) {
      const size_t at = (p * size_t(n) + size_t(c)) * size_t(bytes);
      ch[c] = bytes == 1 ? img.image[at] : uint8_t((img.image[at] | (img.image[at + 1] << 8)) >> 8);
    }
    uint8_t* d = &out.data[p * 4];
    if (n <= 2) {  // grey (+ alpha)
      d[0] = d[1] = d[2] = ch[0];
      d[3] = n == 2 ? ch[1] : 255;
    } else {
      std::memcpy(d, ch, 4);
    }
  }
  return out;
}

Expected<int> texture_for(LoadContext& ctx, int gltf_texture) {
  if (gltf_texture < 0) return -1;
  auto it = ctx.texture_of_gltf_texture.find(gltf_texture);
  if (it != ctx.texture_of_gltf_texture.end()) return it->second;
  const auto& m = ctx.gltf;
  if (size_t(gltf_texture) >= m.textures.size())
    return fail(ErrorKind::BadInput, ctx.path + ": texture " + std::to_string(gltf_texture) + " does not exist");
  const int source = m.textures[size_t(gltf_texture)].source;
  if (source < 0 || size_t(source) >= m.images.size())
    return fail(ErrorKind::BadInput, ctx.path + ": texture " + std::to_string(gltf_texture) +
                                         " has no valid image source");
  auto rgba = to_rgba8(ctx, m.images[size_t(source)], source);
  if (!rgba) return rgba.error();
  ctx.out->textures.push_back(Texture{std::move(*rgba)});
  const int ours = int(ctx.out->textures.size()) - 1;
  ctx.texture_of_gltf_texture[gltf_texture] = ours;
  return ours;
}

double extension_number(const tinygltf::ExtensionMap& ext, const char* name, const char* key,
                        double fallback) {
  auto it = ext.find(name);
  if (it == ext.end() || !it->second.Has(key)) return fallback;
  const auto& v = it->second.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// Element `index` of a numeric array in an extension, or `fallback`.
double extension_number_at(const tinygltf::ExtensionMap& ext, const char* name, const char* key, int index,
                           double fallback) {
  auto it = ext.find(name);
  if (it == ext.end() || !it->second.Has(key)) return fallback;
  const auto& v = it->second.Get(key);
  if (!v.IsArray() || index >= int(v.ArrayLen())) return fallback;
  const auto& e = v.Get(index);
  return e.IsNumber() ? e.GetNumberAsDouble() : fallback;
}

Status convert_materials(LoadContext& ctx) {
  for (size_t i = 0; i < ctx.gltf.materials.size(); ++i) {
    const auto& g = ctx.gltf.materials[i];
    const auto& pbr = g.pbrMetallicRoughness;
    Material mat;
    for (int c = 0; c < 4 && c < int(pbr.baseColorFactor.size()); ++c)
      mat.base_color_factor[c] = float(pbr.baseColorFactor[size_t(c)]);
    auto tex = texture_for(ctx, pbr.baseColorTexture.index);
    if (!tex) return tex.error();
    mat.base_color_texture = *tex;
    mat.metallic = float(pbr.metallicFactor);
    mat.roughness = float(pbr.roughnessFactor);
    const double emissive_strength =
        extension_number(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
    for (int c = 0; c < 3 && c < int(g.emissiveFactor.size()); ++c)
      mat.emissive[c] = float(g.emissiveFactor[size_t(c)] * emissive_strength);
    auto emissive_tex = texture_for(ctx, g.emissiveTexture.index);
    if (!emissive_tex) return emissive_tex.error();
    mat.emissive_texture = *emissive_tex;
    mat.double_sided = g.doubleSided;
    mat.transmission = float(extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0));
    mat.ior = float(extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5));
    for (int c = 0; c < 3; ++c)
      mat.attenuation_color[c] = float(extension_number_at(g.extensions, "KHR_materials_volume", "attenuationColor", c, 1.0));
    mat.attenuation_distance =
        float(extension_number(g.extensions, "KHR_materials_volume", "attenuationDistance", 0.0));
    const std::string label = "material " + std::to_string(i) + (g.name.empty() ? "" : " '" + g.name + "'");
    if (!(mat.transmission >= 0.0f && mat.transmission <= 1.0f))
      return fail(ErrorKind::BadInput, ctx.path + ": " + label +
                                           ": KHR_materials_transmission.transmissionFactor must be in [0, 1]");
    if (!(mat.ior >= 1.0f && mat.ior <= 4.0f))
      return fail(ErrorKind::BadInput, ctx.path + ": " + label + ": KHR_materials_ior.ior must be in [1, 4]");
    if (!(mat.attenuation_distance >= 0.0f) || !std::isfinite(mat.attenuation_distance))
      return fail(ErrorKind::BadInput, ctx.path + ": " + label +
                                           ": KHR_materials_volume.attenuationDistance must be a positive number");
    for (int c = 0; c < 3; ++c)
      if (!(mat.attenuation_color[c] >= 0.0f && mat.attenuation_color[c] <= 1.0f))
        return fail(ErrorKind::BadInput, ctx.path + ": " + label +
                                             ": KHR_materials_volume.attenuationColor must be in [0, 1]");
    ctx.out->materials.push_back(mat);
  }
  return ok_status();
}

glm::dmat4 node_local_matrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3)
    m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  if (node.rotation.size() == 4) {
    const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    const glm::dmat4 r = glm::mat4_cast(glm::normalize(q));
    m = m * r;
  }
  if (node.scale.size() == 3) {
    m[0] *= node.scale[0];
    m[1] *= node.scale[1];
    m[2] *= node.scale[2];
  }
  return m;
}

// A texture's coordinate set and KHR_texture_transform (offset, rotation, scale: uv' = offset +
// R(rotation) (scale * uv), R counter-clockwise, the extension's matrix T * R * S). The base
// colour and the emissive texture are the ones mrgi samples, both through the primitive's one
// set of coordinates, so the transform is applied to those coordinates once at load instead of
// per texel lookup (and the two textures must agree on it: material_uv_transform).
struct UvTransform {
  int tex_coord = 0;
  glm::dvec2 offset{0.0}, scale{1.0};
  double rotation = 0.0;
  bool identity() const { return offset == glm::dvec2(0.0) && scale == glm::dvec2(1.0) && rotation == 0.0; }
  bool operator==(const UvTransform& o) const {
    return tex_coord == o.tex_coord && offset == o.offset && scale == o.scale && rotation == o.rotation;
  }
  glm::vec2 apply(glm::vec2 uv) const {
    const glm::dvec2 s = glm::dvec2(uv) * scale;
    const double c = std::cos(rotation), n = std::sin(rotation);
    return glm::vec2(offset + glm::dvec2(c * s.x - n * s.y, n * s.x + c * s.y));
  }
};

Expected<UvTransform> texture_uv_transform(const tinygltf::TextureInfo& info, const std::string& where) {
  UvTransform t;
  t.tex_coord = info.texCoord;
  auto it = info.extensions.find("KHR_texture_transform");
  if (it != info.extensions.end()) {
    const tinygltf::Value& ext = it->second;
    const std::string field = where + ".extensions.KHR_texture_transform.";
    auto pair = [&](const char* key, glm::dvec2& out) -> Status {
      if (!ext.Has(key)) return ok_status();
      const auto& v = ext.Get(key);
      if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
        return fail(ErrorKind::BadInput, field + key + ": must be an array of 2 numbers");
      out = glm::dvec2(v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble());
      if (!std::isfinite(out.x) || !std::isfinite(out.y) || std::abs(out.x) > 1e6 || std::abs(out.y) > 1e6)
        return fail(ErrorKind::BadInput, field + key + ": must be finite and within +-1e6");
      return ok_status();
    };
    MRGI_TRY(pair("offset", t.offset));
    MRGI_TRY(pair("scale", t.scale));
    if (ext.Has("rotation")) {
      const auto& r = ext.Get("rotation");
      if (!r.IsNumber() || !std::isfinite(r.GetNumberAsDouble()))
        return fail(ErrorKind::BadInput, field + "rotation: must be a finite number (radians)");
      t.rotation = r.GetNumberAsDouble();
    }
    if (ext.Has("texCoord")) {
      const auto& c = ext.Get("texCoord");
      if (!c.IsInt() || c.GetNumberAsInt() < 0)
        return fail(ErrorKind::BadInput, field + "texCoord: must be a non-negative integer");
      t.tex_coord = c.GetNumberAsInt();
    }
  }
  if (t.tex_coord < 0)
    return fail(ErrorKind::BadInput, where + ".texCoord: must be a non-negative integer");
  return t;
}

// The coordinates a primitive of `material` needs: its base colour texture's, else its emissive
// texture's; both present with different sets or transforms is refused (one set of coordinates
// per vertex is kept).
Expected<UvTransform> material_uv_transform(const LoadContext& ctx, int material) {
  if (material < 0 || size_t(material) >= ctx.gltf.materials.size()) return UvTransform{};
  const auto& m = ctx.gltf.materials[size_t(material)];
  const std::string where = ctx.path + ": materials[" + std::to_string(material) + "]";
  const auto& base = m.pbrMetallicRoughness.baseColorTexture;
  const auto& emissive = m.emissiveTexture;
  std::optional<UvTransform> b, e;
  if (base.index >= 0) {
    auto t = texture_uv_transform(base, where + ".pbrMetallicRoughness.baseColorTexture");
    if (!t) return t.error();
    b = *t;
  }
  if (emissive.index >= 0) {
    auto t = texture_uv_transform(emissive, where + ".emissiveTexture");
    if (!t) return t.error();
    e = *t;
  }
  if (b && e && !(*b == *e))
    return fail(ErrorKind::NotImplemented,
                where + ": the emissive texture reads other texture coordinates (texCoord or "
                        "KHR_texture_transform) than the base colour texture; mrgi keeps one set per "
                        "vertex");
  return b ? *b : (e ? *e : UvTransform{});
}

Status add_primitive(LoadContext& ctx, int mesh_index, size_t prim_index, const glm::dmat4& world) {
  const auto& prim = ctx.gltf.meshes[size_t(mesh_index)].primitives[prim_index];
  const std::string what = mesh_label(ctx.gltf, mesh_index, prim_index);
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES)
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": primitive mode '" + mode_name(mode) +
                                         "' is not supported (triangle lists only)");
  auto pos_it = prim.attributes.find("POSITION");
  if (pos_it == prim.attributes.end())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": has no POSITION attribute");
  auto positions = read_vectors<3>(ctx, pos_it->second, what + " POSITION");
  if (!positions) return positions.error();
  std::vector<glm::vec3> normals;
  if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
    auto n = read_vectors<3>(ctx, it->second, what + " NORMAL");
    if (!n) return n.error();
    normals = std::move(*n);
  }
  auto uv_transform = material_uv_transform(ctx, prim.material);
  if (!uv_transform) return uv_transform.error();
  std::vector<glm::vec2> uvs;
  const std::string uv_name = "TEXCOORD_" + std::to_string(uv_transform->tex_coord);
  if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
    auto t = read_vectors<2>(ctx, it->second, what + " " + uv_name);
    if (!t) return t.error();
    uvs = std::move(*t);
    if (!uv_transform->identity())
      for (glm::vec2& uv : uvs) uv = uv_transform->apply(uv);
  } else if (uv_transform->tex_coord != 0) {
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": its material's texture reads " +
                                         uv_name + ", which the primitive does not have");
  }
  const size_t vcount = positions->size();
  if ((!normals.empty() && normals.size() != vcount) || (!uvs.empty() && uvs.size() != vcount))
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": attribute counts differ from POSITION's");
  auto indices = read_indices(ctx, prim.indices, vcount, what);
  if (!indices) return indices.error();
  if (indices->size() % 3 != 0)
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": index count " +
                                         std::to_string(indices->size()) + " is not a multiple of 3");
  if (indices->empty())
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": has no triangles (zero indices or vertices)");
  if (prim.material >= int(ctx.gltf.materials.size()))
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": material " +
                                         std::to_string(prim.material) + " does not exist");

  if (ctx.out->primitives.size() >= gltf::kMaxPrimitives)
    return fail(ErrorKind::BadInput, ctx.path + ": more than " + std::to_string(gltf::kMaxPrimitives) +
                                         " primitive instances in the default scene (limit)");
  const size_t adds = normals.empty() ? indices->size() : vcount;
  if (ctx.vertices + adds > gltf::kMaxVertices)
    return fail(ErrorKind::BadInput, ctx.path + ": " + what + ": the default scene would hold more than " +
                                         std::to_string(gltf::kMaxVertices) + " vertices (limit)");
  ctx.vertices += adds;
  MeshPrimitive out;
  out.material = prim.material;
  const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(world));
  // A mirroring transform turns counter-clockwise triangles clockwise; swap to keep front faces.
  const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
  auto to_world = [&](const glm::vec3& p) { return glm::vec3(world * glm::dvec4(p, 1.0)); };
  auto normal_to_world = [&](const glm::vec3& n) {
    const glm::dvec3 w = normal_matrix * glm::dvec3(n);
    const double len = glm::length(w);
    return len > 0.0 ? glm::vec3(w / len) : glm::vec3(0.0f, 1.0f, 0.0f);
  };
  if (!normals.empty()) {
    out.positions.reserve(vcount);
    out.normals.reserve(vcount);
    for (size_t i = 0; i < vcount; ++i) {
      out.positions.push_back(to_world((*positions)[i]));
      out.normals.push_back(normal_to_world(normals[i]));
    }
    out.uvs = std::move(uvs);
    out.indices = std::move(*indices);
    if (mirrored)
      for (size_t t = 0; t + 2 < out.indices.size(); t += 3) std::swap(out.indices[t + 1], out.indices[t + 2]);
  } else {
    // Flat normals: every triangle gets its own three vertices.
    const size_t n = indices->size();
    out.positions.reserve(n);
    out.normals.reserve(n);
    for (size_t t = 0; t < n; t += 3) {
      size_t corner[3] = {(*indices)[t], (*indices)[t + 1], (*indices)[t + 2]};
      if (mirrored) std::swap(corner[1], corner[2]);
      const glm::vec3 a = to_world((*positions)[corner[0]]), b = to_world((*positions)[corner[1]]),
                      c = to_world((*positions)[corner[2]]);
      const glm::vec3 cr = glm::cross(b - a, c - a);
      const float len = glm::length(cr);
      const glm::vec3 face = len > 0.0f ? cr / len : glm::vec3(0.0f, 1.0f, 0.0f);
      for (int k = 0; k < 3; ++k) {
        out.positions.push_back(k == 0 ? a : k == 1 ? b : c);
        out.normals.push_back(face);
        if (!uvs.empty()) out.uvs.push_back(uvs[corner[k]]);
        out.indices.push_back(uint32_t(t + size_t(k)));
      }
    }
  }
  for (const glm::vec3& p : out.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return fail(ErrorKind::BadInput, ctx.path + ": mesh " + std::to_string(mesh_index) + " primitive " +
                                           std::to_string(prim_index) +
                                           ": a position is not finite as a 32-bit float once its node's transform "
                                           "is applied (scale or translation too large)");
  ctx.out->primitives.push_back(std::move(out));
  return ok_status();
}

Status visit_node(LoadContext& ctx, int node_index, const glm::dmat4& parent, int depth) {
  if (node_index < 0 || size_t(node_index) >= ctx.gltf.nodes.size())
    return fail(ErrorKind::BadInput, ctx.path + ": node " + std::to_string(node_index) + " does not exist");
  if (depth > kMaxNodeDepth)
    return fail(ErrorKind::BadInput, ctx.path + ": node " + std::to_string(node_index) +
                                         ": node tree deeper than " + std::to_string(kMaxNodeDepth) +
                                         " (a cycle?)");
  // A node listed twice as a child at every level expands to 2^depth instances: bounded.
  if (++ctx.node_visits > gltf::kMaxNodeVisits)
    return fail(ErrorKind::BadInput, ctx.path + ": the node tree expands to more than " +
                                         std::to_string(gltf::kMaxNodeVisits) +
                                         " node instances (limit; nodes listed as children of several parents "
                                         "are instanced once per path)");
  const auto& node = ctx.gltf.nodes[size_t(node_index)];
  // The runtime keeps transforms and positions as 32-bit floats: a value that is finite only as a
  // double (a scale of 1e39) would become infinite vertices, so it is refused naming the field.
  const std::pair<const char*, const std::vector<double>*> fields[] = {
      {"matrix", &node.matrix}, {"translation", &node.translation}, {"rotation", &node.rotation}, {"scale", &node.scale}};
  for (const auto& [name, values] : fields)
    for (size_t k = 0; k < values->size(); ++k)
      if (!std::isfinite(float((*values)[k])))
        return fail(ErrorKind::BadInput, ctx.path + ": node " + std::to_string(node_index) + ": " + name + "[" +
                                             std::to_string(k) + "] = " + std::to_string((*values)[k]) +
                                             " is not a finite 32-bit float (|value| at most 3.4e38)");
  const glm::dmat4 world = parent * node_local_matrix(node);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(float(world[c][r])))
        return fail(ErrorKind::BadInput, ctx.path + ": node " + std::to_string(node_index) +
                                             ": its world transform (its ancestors' times its own) is not finite "
                                             "as 32-bit floats");
  if (node.mesh >= 0) {
    if (size_t(node.mesh) >= ctx.gltf.meshes.size())
      return fail(ErrorKind::BadInput, ctx.path + ": node " + std::to_string(node_index) + ": mesh " +
                                           std::to_string(node.mesh) + " does not exist");
    for (size_t p = 0; p < ctx.gltf.meshes[size_t(node.mesh)].primitives.size(); ++p)
      MRGI_TRY(add_primitive(ctx, node.mesh, p, world));
  }
  for (int child : node.children) MRGI_TRY(visit_node(ctx, child, world, depth + 1));
  return ok_status();
}

}  // namespace

Expected<Model> load_gltf(const std::string& path, const Placement& placement) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(ErrorKind::NotFound, path + ": glTF file does not exist");
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".gltf" && ext != ".glb")
    return fail(ErrorKind::BadInput, path + ": expected a .gltf or .glb file, got '" + ext + "'");

  // Read and bounded here, parsed by tinygltf with file access confined to the model's folder
  // (scene/gltf_input.h).
  auto input = gltf::read_input(path, ext == ".glb");
  if (!input) return input.error();
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(gltf::confined_fs(&input->base_dir));
  gltf::ImageLoaderState images;
  loader.SetImageLoader(&gltf::load_image, &images);
  tinygltf::Model gltf;
  std::string err, warn;
  const bool loaded =
      input->binary
          ? loader.LoadBinaryFromMemory(&gltf, &err, &warn, input->bytes.data(),
                                        unsigned(input->bytes.size()), input->base_dir)
          : loader.LoadASCIIFromString(&gltf, &err, &warn,
                                       reinterpret_cast<const char*>(input->bytes.data()),
                                       unsigned(input->bytes.size()), input->base_dir);
  if (!loaded) {
    if (!err.empty() && err.back() == '\n') err.pop_back();
    return fail(ErrorKind::BadInput, path + ": cannot load glTF: " + (err.empty() ? warn : err));
  }
  input->bytes = {};
  // An extension the file requires changes how it must be read (Draco-compressed geometry
  // otherwise reads as "accessor invalid bufferView"); none is implemented, so each is refused
  // by name.
  if (!gltf.extensionsRequired.empty())
    return fail(ErrorKind::NotImplemented, path + ": requires the glTF extension '" +
                                               gltf.extensionsRequired.front() +
                                               "', which mrgi does not support (extensionsRequired)");
  if (gltf.asset.version.rfind("2.", 0) != 0)
    return fail(ErrorKind::BadInput, path + ": glTF version '" + gltf.asset.version +
                                         "' (asset.version): only glTF 2.0 is read");
  if (gltf.scenes.empty())
    return fail(ErrorKind::BadInput, path + ": the file has no scene (glTF 'scenes' is empty)");
  const int scene_index = gltf.defaultScene >= 0 ? gltf.defaultScene : 0;
  if (size_t(scene_index) >= gltf.scenes.size())
    return fail(ErrorKind::BadInput, path + ": default scene " + std::to_string(scene_index) + " does not exist");

  Model model;
  LoadContext ctx{path, gltf, &model, {}};
  MRGI_TRY(convert_materials(ctx));
  const glm::dmat4 root = glm::dmat4(placement.matrix());
  for (int node : gltf.scenes[size_t(scene_index)].nodes) MRGI_TRY(visit_node(ctx, node, root, 0));
  if (model.primitives.empty())
    return fail(ErrorKind::BadInput, path + ": the default scene holds no triangle geometry");

  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const auto& prim : model.primitives)
    for (const auto& p : prim.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  if (lo.x > hi.x)
    return fail(ErrorKind::BadInput, path + ": the default scene holds no vertices");
  model.bounds_min = lo;
  model.bounds_max = hi;
  return model;
}

}  // namespace mrgi
