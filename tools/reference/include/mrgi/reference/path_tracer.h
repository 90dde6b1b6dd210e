// The path-traced ground truth (docs/DESIGN.md "Ground truth and error"): an Embree 3 path tracer that
// renders the real-only scene (L_r) and the real+virtual scene (L_rv) of a mixed-reality setup
// with the same random numbers, so that L_rv - L_r is low-noise.
//
// How L_r and L_rv share random numbers: every random number is a hash of (seed, frame, pixel,
// sample, bounce, slot), never a sequential stream, so the same sample of the same pixel draws the
// same numbers in both scenes. Each sample is traced once through the real+virtual scene; if the
// path never met anything virtual (no virtual hit, no shadow ray blocked only by a virtual object,
// no virtual lamp) it is bit-for-bit the path the real-only scene would trace, and L_r reuses it.
// Only samples that touched something virtual are traced again in the real-only scene. The
// difference is therefore exactly zero where no virtual object matters (DIR paper, section 3.1).
//
// Light transport: unidirectional path tracing with next-event estimation toward every lamp at
// every non-specular vertex, multiple importance sampling (balance heuristic) between BSDF
// sampling and light sampling for area lamps and the environment, Russian roulette after
// `rr_depth` bounces. Delta lamps seen only through delta BSDFs (caustics of a point lamp through
// glass) cannot be sampled by this estimator; a light tracer adds them for pinhole cameras:
// photons from each point or spot lamp towards the delta-material meshes, followed through the
// delta vertices after the lamp and connected to the camera at every non-delta vertex after
// those (L S+ (D|S)* E paths, which the pixel estimator never forms: its next-event estimation
// needs a non-delta vertex next to the lamp). Directional lamps' caustics and those seen by the
// environment cameras are still missing.
//
// Materials (radiometric conventions: radiance in W/(m^2 sr) per linear RGB channel):
//   Diffuse  Lambertian, f = albedo / pi.
//   Glossy   glTF metallic-roughness: Lambertian base weighted by (1 - metallic) * (1 - 0.04),
//            plus a GGX microfacet lobe (alpha = roughness^2, Smith height-correlated G2, Schlick
//            Fresnel with F0 = mix(0.04, base colour, metallic)). Single scattering only, so rough
//            metals lose some energy (Kulla & Conty 2017); not compensated.
//   Mirror   perfect specular reflection, reflectance = base colour.
//   Glass    smooth dielectric: exact unpolarised Fresnel, refraction by Snell with `ior`,
//            transmission tinted by base colour, total internal reflection.
//   Emission emitted radiance from the front face (counter-clockwise winding) of any material.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi::reference {

enum class MaterialType { Diffuse, Glossy, Mirror, Glass };

struct RefMaterial {
  MaterialType type = MaterialType::Diffuse;
  glm::vec3 base_color{0.8f};  // linear RGB albedo / reflectance / transmission tint, in [0, 1]
  int texture = -1;            // index into RefScene::textures (linear), multiplies base_color
  float roughness = 0.5f;      // Glossy: perceptual roughness, GGX alpha = roughness^2
  float metallic = 0.0f;       // Glossy: 0 dielectric .. 1 metal
  float ior = 1.5f;            // Glass: index of refraction (outside is 1)
  glm::vec3 emission{0.0f};    // emitted radiance, W/(m^2 sr) per channel, front face
};

// A triangle mesh in world space. Counter-clockwise winding seen from the front (as glTF).
struct RefMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // per vertex, for shading; empty = flat (geometric) normals
  std::vector<glm::vec2> uvs;      // per vertex; empty = no texture coordinates
  std::vector<uint32_t> indices;   // triangle list
  int material = 0;                // index into RefScene::materials
  bool is_virtual = false;         // part of the virtual objects (absent from L_r)
};

enum class RefLightType { Point, Spot, Directional };

// Delta lamps. Area lamps are emissive meshes (RefMaterial::emission), sampled by area.
struct RefLight {
  RefLightType type = RefLightType::Point;
  bool is_virtual = false;
  glm::vec3 position{0.0f};                // world, metres (point, spot)
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // unit, where the light goes (spot, directional)
  glm::vec3 intensity{1.0f};               // W/sr per channel (point, spot); W/m^2 (directional)
  float cos_inner = 1.0f;                  // spot: full intensity where cos(angle) >= cos_inner
  float cos_outer = 0.0f;                  // spot: zero where cos(angle) <= cos_outer
};

// Equirectangular environment in linear radiance, always real. Direction d (environment space,
// +y up) maps to u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi (u right, v down), so
// the image centre looks along -z and the top row is straight up.
struct RefEnvironment {
  ImageRGBF image;              // empty = no environment (black)
  float intensity = 1.0f;       // radiance multiplier
  glm::mat3 rotation{1.0f};     // environment-to-world
};

struct RefScene {
  std::vector<RefMaterial> materials;
  std::vector<RefMesh> meshes;
  std::vector<RefLight> lights;
  RefEnvironment environment;
  std::vector<ImageRGBF> textures;  // linear RGB, sampled bilinearly with repeat wrapping
};

// The camera the image is rendered through. Pose is camera-to-world in the OpenCV/TUM convention
// (x right, y down, looking along +z).
struct RefCamera {
  // Equirectangular: the whole sphere around the camera's position in the environment mapping
  // above (width x height, camera_to_world's rotation applied), e.g. a light probe.
  enum class Model { Pinhole, FisheyeEquidistant, Equirectangular } model = Model::Pinhole;
  Intrinsics pinhole;                   // Pinhole: pixel intrinsics (width and height used)
  int width = 256, height = 256;        // Fisheye, Equirectangular: image size
  double fisheye_f = 0.0, fisheye_cx = 0.0, fisheye_cy = 0.0;  // Fisheye: r = f * theta
  double fisheye_fov_deg = 180.0;       // Fisheye: full field of view; outside it is black
  glm::dmat4 camera_to_world{1.0};
  int image_width() const { return model == Model::Pinhole ? pinhole.width : width; }
  int image_height() const { return model == Model::Pinhole ? pinhole.height : height; }
};

struct RenderSettings {
  int spp = 16;            // samples per pixel, >= 1
  int max_depth = 8;       // indirect bounces, >= 0 (0 = emitters seen directly and direct light)
  int rr_depth = 3;        // Russian roulette from this bounce on
  uint64_t seed = 1;       // with frame and pixel, keys every random number
  uint64_t frame = 0;
  int threads = 0;         // worker threads over 16x16 tiles; 0 = hardware concurrency
  bool real_only = false;  // render only L_r (env camera): `combined` is left empty
  // Light-traced paths per delta lamp per frame (pinhole cameras): the caustics the pixel
  // estimator cannot sample; 0 = spp x pixels / 4.
  uint64_t light_paths = 0;
  // Called from the calling thread about every 0.5 s with (tiles done, tiles total).
  std::function<void(size_t, size_t)> progress;
};

struct RenderOutput {
  ImageRGBF real;          // L_r, linear radiance
  ImageRGBF combined;      // L_rv, linear radiance
  ImageU8 virtual_mask;    // 255 where the pixel-centre primary ray hits a virtual object first
  // From the pixel-centre primary ray in the real-only scene (what a depth sensor sees):
  std::vector<float> depth_z;       // metres along the optical axis, 0 = no hit
  std::vector<float> cos_incidence; // |cos| between the ray and the surface normal, 0 = no hit
  size_t dropped_samples = 0;       // non-finite samples discarded (should stay 0)
};

class PathTracer {
 public:
  // Builds the acceleration structures and light-sampling tables. Refuses meshes with indices out
  // of range, material indices out of range, NaN vertices or non-finite lamp values.
  static Expected<std::unique_ptr<PathTracer>> create(const RefScene& scene);
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  Expected<RenderOutput> render(const RefCamera& camera, const RenderSettings& settings) const;

  struct Impl;

 private:
  explicit PathTracer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mrgi::reference
