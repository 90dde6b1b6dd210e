/// \file
/// scene.json v1 (docs/DESIGN.md) and the glTF 2.0 content it places.
/// Units: metres, radians only where named *_rad, degrees where named *_deg; colours linear RGB.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "mrgi/export.h"
#include "mrgi/glm_contract.h"

#include "mrgi/expected.h"
#include "mrgi/image.h"

namespace mrgi {

struct MRGI_API Placement {
  glm::vec3 position{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  ///< JSON gives x y z w; stored in glm's w,x,y,z
  glm::vec3 scale{1.0f};                      ///< JSON accepts a number (uniform) or [x, y, z]
  glm::mat4 matrix() const;                   ///< object-to-world
};

/// A keyframe of an object's motion: its placement at `time_s` (seconds, the frames' timestamp
/// clock).
struct PoseKey {
  double time_s = 0.0;
  Placement placement;
};

struct VirtualObjectDesc {
  std::string gltf;  ///< absolute path (resolved against the scene file's folder when loaded)
  Placement placement;  ///< where it is at start-up (and always, without motion)
  /// Keyframed motion (scene.json "motion"), times strictly increasing: each frame the runtime
  /// places the object at the frame's timestamp, position and scale interpolated linearly,
  /// rotation by slerp, held at the first and last keys outside them. Empty: it stays put (an
  /// app can still move it, Runtime::set_object_placement).
  std::vector<PoseKey> motion;
};

/// The placement of keyframed `motion` at time t (see VirtualObjectDesc::motion); `motion` must
/// not be empty.
MRGI_API Placement placement_at(const std::vector<PoseKey>& motion, double t);

enum class LightType { Point, Spot, Directional };
/// A keyframe of a lamp's motion (scene.json lights[].motion): where it is, where it points and
/// how bright it is at `time_s` (the frames' timestamp clock).
struct LampKey {
  double time_s = 0.0;
  glm::vec3 position{0.0f};                 ///< point, spot
  glm::vec3 direction{0.0f, -1.0f, 0.0f};   ///< spot, directional (unit)
  float intensity = 1.0f;                   ///< 0: off
};

struct LightDesc {
  LightType type = LightType::Point;
  bool real = true;                   ///< a real lamp (in the camera image) or a virtual one
  glm::vec3 position{0.0f};           ///< world, metres (point, spot)
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  ///< world, unit (spot, directional: where light goes)
  glm::vec3 color{1.0f};              ///< linear RGB tint, multiplied by intensity
  float intensity = 1.0f;             ///< W/sr (point/spot) or W/m^2 (directional), per channel
  float inner_angle_deg = 30.0f;      ///< spot: full intensity inside this half-angle
  float outer_angle_deg = 45.0f;      ///< spot: zero outside this half-angle
  /// Keyframed motion, times strictly increasing: each frame the runtime sets the lamp to the
  /// frame's timestamp, position and intensity interpolated linearly, direction by the
  /// normalised linear mix, held at the first and last keys outside them. Empty: it stays
  /// (an app can still change it, Runtime::set_lamp, which stops the motion).
  std::vector<LampKey> motion;
};

/// `lamp` as its motion has it at time t (without the motion: no allocation); `lamp.motion` must
/// not be empty.
MRGI_API LightDesc lamp_at(const LightDesc& lamp, double t);

struct EnvironmentDesc {
  bool present = false;
  bool real = true;
  std::string image;                  ///< absolute path, or empty with from_env_camera
  bool from_env_camera = false;       ///< use the capture's env/* stream
  float intensity = 1.0f;
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  ///< environment-to-world
};

/// Hints for real surfaces (the runtime estimates albedo from the camera otherwise).
struct MaterialHint {
  glm::vec3 base_color{0.8f};
  float roughness = 1.0f;
  float metallic = 0.0f;
};

struct RealGeometryDesc {
  std::string gltf;  ///< absolute path
  Placement placement;
  bool has_material_hint = false;
  MaterialHint material;
};

/// A region of the real scene whose surfaces have a known material (scene.json real_materials):
/// the real pixels whose reconstructed positions fall in the axis-aligned box [min, max] (world,
/// metres) take its roughness and metallic (their colour stays the camera's estimate). The first
/// region holding a point wins; real pixels in none are rough dielectrics (Lambert), as before.
/// What a technique with glossy real light transport reads (dvct's specular cone on real pixels).
struct RealMaterialRegion {
  glm::vec3 min{0.0f}, max{0.0f};
  float roughness = 1.0f;  ///< GGX, perceptual (alpha = roughness^2)
  float metallic = 0.0f;
};

struct SceneDesc {
  std::string path;  ///< the scene.json it was read from (for messages)
  std::vector<VirtualObjectDesc> virtual_objects;
  std::vector<LightDesc> lights;
  EnvironmentDesc environment;
  std::vector<RealGeometryDesc> real_geometry;
  std::vector<RealMaterialRegion> real_materials;
};

/// Room for virtual objects an app adds while the runtime runs (Runtime::add_object), beyond
/// scene.json's: stated when the runtime is created, allocated then and never grown. A removed
/// object's room (scene.json's or an added one's) is free for the next added object. The
/// default (all 0) is scene.json's objects only.
struct ObjectCapacity {
  int objects = 0;          ///< slots for added objects (a removed scene.json object's slot takes one too)
  int meshes = 0;           ///< their glTF primitives (draw ranges), in all
  /// Their triangles at full detail, in all. Their levels of detail are reserved at as many
  /// again (what halving simplification gives); a mesh whose simplification keeps more is
  /// refused, naming "triangles (with their levels of detail)".
  uint32_t triangles = 0;
  uint32_t vertices = 0;    ///< their vertices, in all
  int textures = 0;         ///< their base-colour and emissive textures (one array layer each)
  /// Texels a side of each texture layer when scene.json's objects have no larger ones (added
  /// textures are resampled to the array's side), 1..1024.
  int texture_side = 512;
  /// Whether added objects may be glossy (metallic above 0.1 or roughness below 0.7) or emit
  /// light: the passes for them are prepared at start-up (dir's glossy VPLs cost every pixel
  /// whether or not a glossy object is shown). An object needing what was not prepared is
  /// refused, naming its material. Mirrors and glass (specular materials) cannot be added: declare
  /// them in scene.json and show or hide them (Runtime::set_object_visible). With glossy set,
  /// technique "auto" leaves ssrt out (its transfer is diffuse), as for a glossy scene.json object.
  bool glossy = false;
  bool emissive = false;
};

/// Parses and validates scene.json. Unknown keys, wrong types, non-unit quaternions, NaNs,
/// negative intensities or spot angles with inner > outer are refused, naming file, key and rule.
MRGI_API Expected<SceneDesc> load_scene_json(const std::string& path);
MRGI_API Status write_scene_json(const std::string& path, const SceneDesc& scene);

// ---- Loaded glTF content -------------------------------------------------------------------

struct Material {
  glm::vec4 base_color_factor{1.0f};
  int base_color_texture = -1;   ///< index into Model::textures, -1 = none
  float metallic = 1.0f;         ///< glTF defaults
  float roughness = 1.0f;
  float transmission = 0.0f;     ///< KHR_materials_transmission
  float ior = 1.5f;              ///< KHR_materials_ior, [1, 4]
  /// KHR_materials_volume: light inside a transmissive material keeps attenuation_color after
  /// attenuation_distance metres (Beer's law); distance 0 = no absorption (the extension's
  /// infinite default).
  glm::vec3 attenuation_color{1.0f};
  float attenuation_distance = 0.0f;
  glm::vec3 emissive{0.0f};      ///< emitted radiance: emissiveFactor x KHR_materials_emissive_strength
  int emissive_texture = -1;     ///< index into Model::textures (sRGB, multiplies `emissive`), -1 = none
  bool double_sided = false;
};

/// One triangle list in world space after node transforms and the placement are applied.
struct MeshPrimitive {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;      ///< generated from faces when the file has none
  std::vector<glm::vec2> uvs;          ///< empty when the file has none
  std::vector<uint32_t> indices;       ///< triangle list
  int material = -1;                   ///< index into Model::materials; -1 = glTF default material
};

struct Texture {
  ImageRGBA8 image;  ///< sRGB-encoded colour (a base colour or an emissive texture)
};

struct Model {
  std::vector<MeshPrimitive> primitives;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};  ///< world-space AABB
};

/// Loads a .gltf/.glb (tinygltf), flattens the node hierarchy of the default scene and applies
/// `placement` on top. Triangles only; other primitive modes are refused with the mesh's name.
MRGI_API Expected<Model> load_gltf(const std::string& path, const Placement& placement);

}  // namespace mrgi
