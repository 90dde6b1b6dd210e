#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <sys/stat.h>

#include <glm/gtc/matrix_transform.hpp>

#include "capture/temp_dir.h"
#include "mrgi/scene.h"
#include "common/shared_data.h"

namespace mrgi {
namespace {

using testing::TempDir;
using testing::write_text;

const std::string kModels = mrgi::test::shared_data("models/");

void expect_vec3_near(const glm::vec3& a, const glm::vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

size_t vertex_count(const Model& m) {
  size_t n = 0;
  for (const auto& p : m.primitives) n += p.positions.size();
  return n;
}

TEST(GltfLoader, BunnyVerticesBoundsAndMaterial) {
  MRGI_SKIP_WITHOUT_SHARED(kModels);
  auto model = load_gltf(kModels + "bunny.glb", Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->primitives.size(), 1u);
  const auto& prim = model->primitives[0];
  EXPECT_EQ(prim.positions.size(), 8146u);
  EXPECT_EQ(prim.normals.size(), 8146u);
  EXPECT_EQ(prim.indices.size(), 48642u);
  EXPECT_TRUE(prim.uvs.empty());
  expect_vec3_near(model->bounds_min, {-0.0945716f, -0.0618736f, -0.186643f}, 1e-6f);
  expect_vec3_near(model->bounds_max, {0.0609346f, 0.0586895f, -0.0333891f}, 1e-6f);
  ASSERT_EQ(model->materials.size(), 1u);
  const Material& mat = model->materials[size_t(prim.material)];
  EXPECT_NEAR(mat.base_color_factor.g, 0.6f, 1e-6f);
  EXPECT_FLOAT_EQ(mat.metallic, 0.0f);
  EXPECT_NEAR(mat.roughness, 0.8f, 1e-6f);
  EXPECT_TRUE(mat.double_sided);
  EXPECT_EQ(mat.base_color_texture, -1);
  for (const auto& n : prim.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

TEST(GltfLoader, DuckNodeTransformAndTexture) {
  MRGI_SKIP_WITHOUT_SHARED(kModels);
  auto model = load_gltf(kModels + "duck.glb", Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->primitives.size(), 1u);  // the camera node carries no mesh
  const auto& prim = model->primitives[0];
  EXPECT_EQ(prim.positions.size(), 2399u);
  EXPECT_EQ(prim.uvs.size(), 2399u);
  EXPECT_EQ(prim.indices.size(), 12636u);
  // The root node scales centimetres to metres (matrix 0.01).
  expect_vec3_near(model->bounds_min, {-0.692985f, 0.0992937f, -0.613282f}, 1e-5f);
  expect_vec3_near(model->bounds_max, {0.961799f, 1.6397f, 0.539252f}, 1e-5f);
  ASSERT_EQ(model->textures.size(), 1u);
  const Material& mat = model->materials[size_t(prim.material)];
  ASSERT_EQ(mat.base_color_texture, 0);
  const ImageRGBA8& tex = model->textures[0].image;
  EXPECT_EQ(tex.width, 512);
  EXPECT_EQ(tex.height, 512);
  // A yellow duck: the texture's mean is red/green heavy, and alpha is opaque.
  double r = 0, g = 0, b = 0;
  for (size_t i = 0; i < tex.pixel_count(); ++i) {
    r += tex.data[i * 4];
    g += tex.data[i * 4 + 1];
    b += tex.data[i * 4 + 2];
    ASSERT_EQ(tex.data[i * 4 + 3], 255);
  }
  EXPECT_GT(r, 2 * b);
  EXPECT_GT(g, b);
}

TEST(GltfLoader, PlacementIsAppliedOnTop) {
  MRGI_SKIP_WITHOUT_SHARED(kModels);
  Placement p;
  p.position = {10, 0, 0};
  p.scale = glm::vec3(2.0f);
  auto base = load_gltf(kModels + "bunny.glb", Placement{});
  auto moved = load_gltf(kModels + "bunny.glb", p);
  ASSERT_TRUE(base.ok() && moved.ok());
  expect_vec3_near(moved->bounds_min, base->bounds_min * 2.0f + glm::vec3(10, 0, 0), 1e-5f);
  expect_vec3_near(moved->bounds_max, base->bounds_max * 2.0f + glm::vec3(10, 0, 0), 1e-5f);
}

TEST(GltfLoader, CornellBoxMeshesAndIor) {
  MRGI_SKIP_WITHOUT_SHARED(kModels);
  auto model = load_gltf(kModels + "cornell_box.glb", Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->primitives.size(), 8u);
  EXPECT_EQ(vertex_count(*model), 72u);
  expect_vec3_near(model->bounds_min, {0.0f, 0.0f, 0.0f}, 1e-6f);
  expect_vec3_near(model->bounds_max, {0.556f, 0.5488f, 0.5592f}, 1e-6f);
  ASSERT_GE(model->materials.size(), 4u);
  EXPECT_NEAR(model->materials[0].ior, 1.45f, 1e-6f);
  EXPECT_EQ(model->materials[2].base_color_factor, glm::vec4(0, 1, 0, 1));  // green
}

// A hand-written .gltf: one triangle, no normals (flat normals must be generated), a TRS node
// under a parent, byte-strided positions and a transmissive glass material.
struct TinyGltf {
  TempDir dir;
  std::string path;
  // `extensions`: the material's extensions object.
  explicit TinyGltf(const std::string& mode = "4",
                    const std::string& extensions = R"({"KHR_materials_transmission": {"transmissionFactor": 0.95},
                                "KHR_materials_ior": {"ior": 1.33}})") {
    // Positions with a 16-byte stride (4 bytes of padding after each vec3).
    const float data[] = {0, 0, 0, -1, 1, 0, 0, -1, 0, 1, 0, -1};
    std::ofstream(dir.file("tri.bin"), std::ios::binary)
        .write(reinterpret_cast<const char*>(data), sizeof(data));
    path = dir.file("tri.gltf");
    write_text(path, R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"children": [1], "translation": [0, 1, 0]},
            {"mesh": 0, "rotation": [0, 0.7071068, 0, 0.7071068], "scale": [2, 2, 2]}],
  "meshes": [{"name": "glass_tri", "primitives": [{"attributes": {"POSITION": 0}, "material": 0, "mode": )" +
                         mode + R"(}]}],
  "materials": [{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.95, 1, 1],
                 "metallicFactor": 0, "roughnessFactor": 0.05},
                 "emissiveFactor": [0.1, 0.2, 0.3],
                 "extensions": )" + extensions + R"(}],
  "buffers": [{"uri": "tri.bin", "byteLength": 48}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 16}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]
})");
  }
};

TEST(GltfLoader, TinyFileWithTransmissionTrsAndFlatNormals) {
  TinyGltf f;
  auto model = load_gltf(f.path, Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->primitives.size(), 1u);
  const auto& prim = model->primitives[0];
  ASSERT_EQ(prim.positions.size(), 3u);
  // Node: rotate 90 deg about +y, scale 2, then the parent lifts by 1: (1,0,0) -> (0,1,-2).
  expect_vec3_near(prim.positions[0], {0, 1, 0}, 1e-5f);
  expect_vec3_near(prim.positions[1], {0, 1, -2}, 1e-5f);
  expect_vec3_near(prim.positions[2], {0, 3, 0}, 1e-5f);
  // The triangle faces +z before the rotation, so +x after it.
  for (const auto& n : prim.normals) expect_vec3_near(n, {1, 0, 0}, 1e-5f);
  EXPECT_EQ(prim.indices, (std::vector<uint32_t>{0, 1, 2}));
  const Material& mat = model->materials[0];
  EXPECT_NEAR(mat.transmission, 0.95f, 1e-6f);
  EXPECT_NEAR(mat.ior, 1.33f, 1e-6f);
  EXPECT_NEAR(mat.roughness, 0.05f, 1e-6f);
  EXPECT_NEAR(mat.emissive.z, 0.3f, 1e-6f);
  EXPECT_FALSE(mat.double_sided);
  expect_vec3_near(model->bounds_min, {0, 1, -2}, 1e-5f);
  expect_vec3_near(model->bounds_max, {0, 3, 0}, 1e-5f);
}

TEST(GltfLoader, VolumeAttenuationIsReadAndBadTransmissionValuesAreRefused) {
  {
    TinyGltf f("4", R"({"KHR_materials_transmission": {"transmissionFactor": 1},
                        "KHR_materials_volume": {"attenuationColor": [0.5, 0.8, 1.0], "attenuationDistance": 0.2}})");
    auto model = load_gltf(f.path, Placement{});
    ASSERT_TRUE(model.ok()) << model.error().message;
    expect_vec3_near(model->materials[0].attenuation_color, {0.5f, 0.8f, 1.0f}, 1e-6f);
    EXPECT_NEAR(model->materials[0].attenuation_distance, 0.2f, 1e-6f);
    EXPECT_NEAR(model->materials[0].ior, 1.5f, 1e-6f);  // KHR_materials_ior's default
  }
  {
    TinyGltf f("4", R"({"KHR_materials_ior": {"ior": 0.5}})");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "material 0 'glass'", "KHR_materials_ior.ior",
                 "[1, 4]");
  }
  {
    TinyGltf f("4", R"({"KHR_materials_transmission": {"transmissionFactor": 1.5}})");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "transmissionFactor", "[0, 1]");
  }
  {
    TinyGltf f("4", R"({"KHR_materials_volume": {"attenuationDistance": -1}})");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "attenuationDistance", "positive");
  }
  {
    TinyGltf f("4", R"({"KHR_materials_volume": {"attenuationColor": [2, 0, 0]}})");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "attenuationColor", "[0, 1]");
  }
}

// Transforms are kept as 32-bit floats: a node value finite only as a double, a world transform
// whose product overflows, or a position that does once transformed is refused, naming the node
// or primitive and the field; never infinite vertices.
TEST(GltfHardening, TransformsBeyondFloatRangeAreRefusedNamingTheField) {
  auto with = [](TinyGltf& f, const std::string& parent, const std::string& child) {
    std::ifstream in(f.path);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    text.replace(text.find(R"("translation": [0, 1, 0])"), 24, parent);
    text.replace(text.find(R"("scale": [2, 2, 2])"), 18, child);
    write_text(f.path, text);
  };
  {
    TinyGltf f;
    with(f, R"("translation": [0, 1, 0])", R"("scale": [1e39, 1, 1])");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "node 1", "scale[0]", "finite 32-bit float");
  }
  {
    TinyGltf f;
    with(f, R"("scale": [1e20, 1e20, 1e20])", R"("scale": [1e20, 1e20, 1e20])");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "node 1", "world transform", "not finite");
  }
  {
    TinyGltf f;
    with(f, R"("translation": [0, 3e38, 0])", R"("scale": [3e38, 3e38, 3e38])");
    EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "mesh 0 primitive 0", "position",
                 "not finite");
  }
  {
    TinyGltf f;  // large but representable: loads
    with(f, R"("translation": [0, 1, 0])", R"("scale": [1e30, 1e30, 1e30])");
    EXPECT_TRUE(load_gltf(f.path, Placement{}).ok());
  }
}

TEST(GltfLoader, MirroringPlacementKeepsFrontFaces) {
  TinyGltf f;
  Placement mirror;
  mirror.scale = {-1, 1, 1};
  auto model = load_gltf(f.path, mirror);
  ASSERT_TRUE(model.ok()) << model.error().message;
  const auto& prim = model->primitives[0];
  const glm::vec3 a = prim.positions[prim.indices[0]], b = prim.positions[prim.indices[1]],
                  c = prim.positions[prim.indices[2]];
  // Winding and stored normal agree after the mirror.
  EXPECT_GT(glm::dot(glm::cross(b - a, c - a), prim.normals[0]), 0.0f);
}

TEST(GltfLoader, NonTriangleModeIsRefusedNamingTheMesh) {
  TinyGltf f("0");
  EXPECT_ERROR(load_gltf(f.path, Placement{}), BadInput, "tri.gltf", "'glass_tri'", "points",
               "triangle lists only");
}

TEST(GltfLoader, MissingAndBrokenFiles) {
  TempDir dir;
  EXPECT_ERROR(load_gltf(dir.file("none.glb"), Placement{}), NotFound, "none.glb");
  write_text(dir.file("bad.gltf"), "{ not json");
  EXPECT_ERROR(load_gltf(dir.file("bad.gltf"), Placement{}), BadInput, "bad.gltf", "cannot load glTF");
  write_text(dir.file("x.obj"), "v 0 0 0");
  EXPECT_ERROR(load_gltf(dir.file("x.obj"), Placement{}), BadInput, "x.obj", ".gltf or .glb");
}

// Interleaved vertices (float position + normalised u16 UV + normalised i8 normal, 20-byte
// stride) and u8 indices: the component types and strides glTF allows besides plain floats.
TEST(GltfLoader, InterleavedNormalisedAttributesAndByteIndices) {
  TempDir dir;
  struct Vertex {
    float pos[3];
    uint16_t uv[2];
    int8_t normal[4];  // xyz + padding to keep 4-byte alignment
  };
  static_assert(sizeof(Vertex) == 20);
  const Vertex verts[3] = {{{0, 0, 0}, {0, 65535}, {0, 0, 127, 0}},
                           {{1, 0, 0}, {65535, 65535}, {0, 0, 127, 0}},
                           {{0, 1, 0}, {0, 0}, {0, -128, 0, 0}}};
  const uint8_t indices[4] = {2, 0, 1, 0};  // one triangle, padded to 4 bytes
  {
    std::ofstream out(dir.file("v.bin"), std::ios::binary);
    out.write(reinterpret_cast<const char*>(verts), sizeof(verts));
    out.write(reinterpret_cast<const char*>(indices), sizeof(indices));
  }
  write_text(dir.file("v.gltf"), R"({
  "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 5,0,0,1]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "NORMAL": 2}, "indices": 3}]}],
  "buffers": [{"uri": "v.bin", "byteLength": 64}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 60, "byteStride": 20},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 3}],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 0, "byteOffset": 12, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC2"},
    {"bufferView": 0, "byteOffset": 16, "componentType": 5120, "normalized": true, "count": 3, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5121, "count": 3, "type": "SCALAR"}]
})");
  auto model = load_gltf(dir.file("v.gltf"), Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  const auto& prim = model->primitives[0];
  EXPECT_EQ(prim.indices, (std::vector<uint32_t>{2, 0, 1}));
  expect_vec3_near(prim.positions[1], {6, 0, 0}, 1e-6f);  // node matrix translates by x = 5
  EXPECT_FLOAT_EQ(prim.uvs[1].x, 1.0f);
  EXPECT_FLOAT_EQ(prim.uvs[1].y, 1.0f);
  EXPECT_FLOAT_EQ(prim.uvs[2].y, 0.0f);
  expect_vec3_near(prim.normals[0], {0, 0, 1}, 1e-6f);
  expect_vec3_near(prim.normals[2], {0, -1, 0}, 1e-6f);  // -128 clamps to -1
  EXPECT_EQ(model->materials.size(), 0u);
  EXPECT_EQ(prim.material, -1);  // the glTF default material
}

TEST(GltfLoader, AccessorPastBufferEndIsRefused) {
  TinyGltf f;
  // Claim 4 vertices in a 48-byte view with a 16-byte stride: the 4th reads past the end.
  std::ifstream in(f.path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("\"count\": 3"), 10, "\"count\": 4");
  write_text(f.path, text);
  auto model = load_gltf(f.path, Placement{});
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().kind, ErrorKind::BadInput);
  EXPECT_TRUE(testing::contains(model.error().message, "tri.gltf")) << model.error().message;
}

}  // namespace
}  // namespace mrgi

namespace mrgi {
namespace {

// A triangle glTF whose JSON the test controls around the fixed parts.
std::string triangle_gltf(const std::string& extra_top, const std::string& nodes, const std::string& buffer_uri) {
  return R"({"asset": {"version": "2.0"}, )" + extra_top + R"(
  "scene": 0, "scenes": [{"nodes": [0]}], "nodes": )" + nodes + R"(,
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"uri": ")" + buffer_uri + R"(", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]})";
}

void write_triangle_bin(const std::string& path) {
  const float tri[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof(tri));
}

// 15,000 nested arrays would overflow the stack inside tinygltf's JSON parser: the nesting depth
// is checked before parsing.
TEST(GltfHardening, DeeplyNestedJsonIsRefusedBeforeParsing) {
  TempDir dir;
  write_triangle_bin(dir.file("t.bin"));
  std::string deep(15000, '[');
  deep += std::string(15000, ']');
  write_text(dir.file("deep.gltf"), triangle_gltf("\"extras\": " + deep + ",", "[{\"mesh\": 0}]", "t.bin"));
  EXPECT_ERROR(load_gltf(dir.file("deep.gltf"), Placement{}), BadInput, "deep.gltf", "nested deeper than 128");
  // Brackets inside strings do not count.
  write_text(dir.file("strings.gltf"),
             triangle_gltf("\"extras\": {\"s\": \"" + std::string(500, '[') + "\\\"[\"},", "[{\"mesh\": 0}]", "t.bin"));
  auto ok = load_gltf(dir.file("strings.gltf"), Placement{});
  EXPECT_TRUE(ok.ok()) << ok.error().message;
}

// A node listed twice as a child per level expands to 2^levels instances: their count is bounded.
TEST(GltfHardening, ExponentialNodeInstancingIsBounded) {
  TempDir dir;
  write_triangle_bin(dir.file("t.bin"));
  std::string nodes = "[";
  const int levels = 40;
  for (int i = 0; i < levels; ++i) nodes += "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]},";
  nodes += "{\"mesh\": 0}]";
  write_text(dir.file("bomb.gltf"), triangle_gltf("", nodes, "t.bin"));
  EXPECT_ERROR(load_gltf(dir.file("bomb.gltf"), Placement{}), BadInput, "bomb.gltf", "node instances", "limit");
}

// URIs outside the model's folder, and FIFOs, are never opened.
TEST(GltfHardening, BufferUrisStayInsideTheModelFolderAndRegularFiles) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("model"));
  write_triangle_bin(dir.file("outside.bin"));
  write_text(dir.file("model/escape.gltf"), triangle_gltf("", "[{\"mesh\": 0}]", "../outside.bin"));
  EXPECT_ERROR(load_gltf(dir.file("model/escape.gltf"), Placement{}), BadInput, "escape.gltf", "outside the model's folder");
  write_text(dir.file("model/abs.gltf"), triangle_gltf("", "[{\"mesh\": 0}]", dir.file("outside.bin")));
  // An absolute URI is resolved under the model's folder, where it does not exist.
  EXPECT_ERROR(load_gltf(dir.file("model/abs.gltf"), Placement{}), BadInput, "abs.gltf", "outside.bin");
  ASSERT_EQ(mkfifo(dir.file("model/fifo.bin").c_str(), 0600), 0);
  write_text(dir.file("model/fifo.gltf"), triangle_gltf("", "[{\"mesh\": 0}]", "fifo.bin"));
  EXPECT_ERROR(load_gltf(dir.file("model/fifo.gltf"), Placement{}), BadInput, "fifo.gltf", "not a regular file");
  // The model file itself as a FIFO or a folder.
  ASSERT_EQ(mkfifo(dir.file("pipe.gltf").c_str(), 0600), 0);
  EXPECT_ERROR(load_gltf(dir.file("pipe.gltf"), Placement{}), NotFound, "pipe.gltf");
}

// A required extension mrgi does not implement is refused by name.
TEST(GltfHardening, RequiredExtensionsAreRefusedByName) {
  TempDir dir;
  write_triangle_bin(dir.file("t.bin"));
  write_text(dir.file("draco.gltf"),
             triangle_gltf("\"extensionsUsed\": [\"KHR_draco_mesh_compression\"], "
                           "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"],",
                           "[{\"mesh\": 0}]", "t.bin"));
  EXPECT_ERROR(load_gltf(dir.file("draco.gltf"), Placement{}), NotImplemented, "draco.gltf",
               "KHR_draco_mesh_compression", "extensionsRequired");
}

// glTF 1.0 is refused as such (not as "no scene"), and so is a primitive without triangles.
TEST(GltfHardening, VersionOneAndEmptyPrimitivesAreNamed) {
  TempDir dir;
  write_triangle_bin(dir.file("t.bin"));
  std::string v1 = triangle_gltf("", "[{\"mesh\": 0}]", "t.bin");
  v1.replace(v1.find("\"2.0\""), 5, "\"1.0\"");
  write_text(dir.file("v1.gltf"), v1);
  EXPECT_ERROR(load_gltf(dir.file("v1.gltf"), Placement{}), BadInput, "v1.gltf", "only glTF 2.0");
  std::string empty = triangle_gltf("", "[{\"mesh\": 0}]", "t.bin");
  empty.replace(empty.find("\"count\": 3"), 10, "\"count\": 0");
  write_text(dir.file("empty.gltf"), empty);
  auto r = load_gltf(dir.file("empty.gltf"), Placement{});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::BadInput) << r.error().message;
}

TEST(GltfHardening, TruncatedOrForeignGlbHeadersAreRefused) {
  TempDir dir;
  std::ofstream(dir.file("short.glb"), std::ios::binary) << "glTF";
  EXPECT_ERROR(load_gltf(dir.file("short.glb"), Placement{}), BadInput, "short.glb", "header");
  // Header claiming more bytes than the file has.
  unsigned char h[20] = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 0xff, 0xff, 0xff, 0x7f, 8, 0, 0, 0, 'J', 'S', 'O', 'N'};
  std::ofstream(dir.file("big.glb"), std::ios::binary).write(reinterpret_cast<const char*>(h), sizeof(h));
  EXPECT_ERROR(load_gltf(dir.file("big.glb"), Placement{}), BadInput, "big.glb", "truncated");
}

}  // namespace
}  // namespace mrgi

namespace mrgi {
namespace {

// KHR_texture_transform on the base colour texture (offset, rotation, scale
// and its texCoord override) is applied to the primitive's coordinates, as the extension's
// T * R * S matrix; bad values are refused naming the field.
std::string textured_triangle_gltf(const std::string& texture_info, const std::string& extra_material = "") {
  return R"({
  "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "extensionsUsed": ["KHR_texture_transform"],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": )" + texture_info + R"(})" + extra_material + R"(}],
  "textures": [{"source": 0}],
  "images": [{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGM4kWIEAANWAV/oF4RSAAAAAElFTkSuQmCC"}],
  "buffers": [{"uri": "uv.bin", "byteLength": 84}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 24}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}]
})";
}

void write_uv_bin(const std::string& path) {
  const float data[21] = {0, 0, 0, 1, 0, 0, 0, 1, 0,  // positions
                          0, 0, 1, 0, 0, 0.5f,        // TEXCOORD_0
                          0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};  // TEXCOORD_1
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data), sizeof(data));
}

TEST(GltfLoader, TextureTransformIsAppliedToTheBaseColourCoordinates) {
  TempDir dir;
  write_uv_bin(dir.file("uv.bin"));
  // Scale (2, 1), then 90 degrees counter-clockwise ((u, v) -> (-v, u)), then offset (0.5, 0):
  // (1, 0) -> (2, 0) -> (0, 2) -> (0.5, 2); (0, 0.5) -> (0, 0.5) -> (-0.5, 0) -> (0, 0).
  write_text(dir.file("t.gltf"), textured_triangle_gltf(
      R"({"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 1.5707963267948966, "scale": [2, 1]}}})"));
  auto model = load_gltf(dir.file("t.gltf"), Placement{});
  ASSERT_TRUE(model.ok()) << model.error().message;
  const auto& uvs = model->primitives[0].uvs;
  ASSERT_EQ(uvs.size(), 3u);
  EXPECT_NEAR(uvs[0].x, 0.5f, 1e-6f);
  EXPECT_NEAR(uvs[0].y, 0.0f, 1e-6f);
  EXPECT_NEAR(uvs[1].x, 0.5f, 1e-6f);
  EXPECT_NEAR(uvs[1].y, 2.0f, 1e-6f);
  EXPECT_NEAR(uvs[2].x, 0.0f, 1e-6f);
  EXPECT_NEAR(uvs[2].y, 0.0f, 1e-6f);

  // The extension's texCoord overrides the texture info's: TEXCOORD_1 (all 0.25), offset only.
  write_text(dir.file("set1.gltf"), textured_triangle_gltf(
      R"({"index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "texCoord": 1}}})"));
  auto set1 = load_gltf(dir.file("set1.gltf"), Placement{});
  ASSERT_TRUE(set1.ok()) << set1.error().message;
  for (const auto& uv : set1->primitives[0].uvs) {
    EXPECT_NEAR(uv.x, 0.75f, 1e-6f);
    EXPECT_NEAR(uv.y, 0.5f, 1e-6f);
  }
  // Without the extension the texture info's own texCoord picks the set.
  write_text(dir.file("plain1.gltf"), textured_triangle_gltf(R"({"index": 0, "texCoord": 1})"));
  auto plain1 = load_gltf(dir.file("plain1.gltf"), Placement{});
  ASSERT_TRUE(plain1.ok()) << plain1.error().message;
  EXPECT_NEAR(plain1->primitives[0].uvs[1].x, 0.25f, 1e-6f);
}

// A texture image that is not there is refused naming the file (not only the
// image's index), and nothing is loaded.
TEST(GltfHardening, AMissingTextureFileIsNamed) {
  TempDir dir;
  write_uv_bin(dir.file("uv.bin"));
  std::string text = textured_triangle_gltf(R"({"index": 0})");
  const std::string data_uri = R"("uri": "data:image/png;base64,)";
  const size_t at = text.find(data_uri);
  ASSERT_NE(at, std::string::npos);
  const size_t end = text.find('"', at + data_uri.size());
  text.replace(at, end + 1 - at, R"("uri": "textures/not_here.png")");
  write_text(dir.file("t.gltf"), text);
  auto model = load_gltf(dir.file("t.gltf"), Placement{});
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().kind, ErrorKind::BadInput) << model.error().message;
  EXPECT_NE(model.error().message.find("not_here.png"), std::string::npos) << model.error().message;
}

TEST(GltfHardening, BadTextureTransformsAreRefusedNamingTheField) {
  TempDir dir;
  write_uv_bin(dir.file("uv.bin"));
  const std::pair<const char*, const char*> cases[] = {
      {R"({"index": 0, "extensions": {"KHR_texture_transform": {"scale": [1]}}})", "scale"},
      {R"({"index": 0, "extensions": {"KHR_texture_transform": {"offset": [1e39, 0]}}})", "offset"},
      {R"({"index": 0, "extensions": {"KHR_texture_transform": {"rotation": "half"}}})", "rotation"},
      {R"({"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": -1}}})", "texCoord"},
      {R"({"index": 0, "texCoord": 5})", "TEXCOORD_5"},
  };
  int i = 0;
  for (const auto& [info, field] : cases) {
    const std::string name = "bad" + std::to_string(i++) + ".gltf";
    write_text(dir.file(name), textured_triangle_gltf(info));
    auto r = load_gltf(dir.file(name), Placement{});
    ASSERT_FALSE(r.ok()) << name;
    EXPECT_EQ(r.error().kind, ErrorKind::BadInput) << r.error().message;
    EXPECT_NE(r.error().message.find(name), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(field), std::string::npos) << r.error().message;
  }
}

TEST(GltfLoader, EmissiveTexturesShareTheBaseColoursCoordinatesOrAreRefused) {
  TempDir dir;
  write_uv_bin(dir.file("uv.bin"));
  // Same coordinates (set 0, no transform): the emissive texture is loaded with the material.
  write_text(dir.file("glow.gltf"), textured_triangle_gltf(
      R"({"index": 0})", R"(, "emissiveFactor": [1, 0.5, 0], "emissiveTexture": {"index": 0})"));
  auto glow = load_gltf(dir.file("glow.gltf"), Placement{});
  ASSERT_TRUE(glow.ok()) << glow.error().message;
  ASSERT_EQ(glow->materials.size(), 1u);
  EXPECT_EQ(glow->materials[0].emissive_texture, 0);
  EXPECT_FLOAT_EQ(glow->materials[0].emissive.y, 0.5f);
  // Another set for the emissive texture than for the base colour: one set per vertex is kept,
  // so this is refused by name.
  write_text(dir.file("two_sets.gltf"), textured_triangle_gltf(
      R"({"index": 0})", R"(, "emissiveTexture": {"index": 0, "texCoord": 1})"));
  EXPECT_ERROR(load_gltf(dir.file("two_sets.gltf"), Placement{}), NotImplemented, "two_sets.gltf",
               "emissive texture", "materials[0]");
}

}  // namespace
}  // namespace mrgi
