// Scene descriptions for `mrgi synth`: a JSON file that says what real world and what virtual
// objects a synthetic capture shows, and how its sensors see them.
//
// Validation is strict, as for scene.json: unknown keys, wrong types, NaN/inf, non-unit
// quaternions, out-of-range values and missing files are refused with "FILE: KEY.PATH: RULE".
// Paths are relative to the description's folder. Units: metres, seconds, degrees where named
// *_deg; colours linear RGB; quaternions [x, y, z, w].
//
//   {
//     "version": 1,                       required, must be 1
//     "frames": 8,                        >= 1 (default 8)
//     "fps": 30,                          frame i is at time i / fps seconds (default 30)
//     "camera": {                         required
//       "width": 640, "height": 480,      pixels (defaults 640 x 480)
//       "fx": 525, "fy": 525,             focal lengths in pixels (default 525)
//       "cx": 319.5, "cy": 239.5,         principal point (default image centre - 0.5)
//       "exposure": 1.0,                  linear radiance -> linear sensor value (default 1)
//       "noise": {"full_well_electrons": 0, "read_noise_electrons": 0}   (mrgi/reference/sensors.h;
//                                         default off)
//     },
//     "camera_path": [                    required, >= 1 keyframe, times strictly increasing;
//       {"time": 0, "position": [x,y,z], "look_at": [x,y,z], "up": [0,1,0]}   position, look-at
//     ],                                  point and up are interpolated linearly, held outside
//     "render": {"spp": 64, "max_depth": 6, "rr_depth": 3, "seed": 1},   (these defaults)
//     "real_objects": [                   real geometry, generated or loaded:
//       {"shape": "plane", "size": [sx, sz]}          x-z rectangle, normal +y
//       {"shape": "box", "size": [sx, sy, sz]}
//       {"shape": "sphere", "radius": r}
//       {"shape": "gltf", "gltf": "file.glb"}         its own materials unless "material" given
//       each with "position" [0,0,0], "rotation" [0,0,0,1], "scale" 1 (number) and "material":
//       {"type": "diffuse"|"glossy"|"mirror"|"glass", "color": [0.8,0.8,0.8], "roughness": 0.5,
//        "metallic": 0, "ior": 1.5, "emission": [0,0,0] (W/(m^2 sr))}; required for shapes
//     ],
//     "lights": [                         lamps; "real" defaults to true
//       {"type": "point", "position", "color": [1,1,1], "intensity": W/sr}
//       {"type": "spot", "position", "direction", "color", "intensity", "inner_angle_deg": 30,
//        "outer_angle_deg": 45}
//       {"type": "directional", "direction", "color", "intensity": W/m^2}
//       {"type": "area", "position", "direction" (where it shines), "size": [w, h], "color",
//        "intensity": radiance W/(m^2 sr)}      a one-sided emissive rectangle, sampled by area;
//                                         scene.json v1 has no area lamps, so it is not listed there
//     ],
//     "environment": {                    optional real surroundings (equirectangular, linear HDR;
//                                         mapping in mrgi/reference/path_tracer.h)
//       "image": "file.exr"               an image file, or
//       "sky": {                          a procedural sun and sky (render_sky below), env axes:
//         "sun_direction": [x,y,z],       towards the sun (normalised; below the horizon allowed)
//         "sun_irradiance": [r,g,b],      W/m^2 at normal incidence (default 3 3 3)
//         "sun_radius_deg": 2,            angular radius of the disc, 0.3..10
//         "zenith": [r,g,b], "horizon": [r,g,b],   sky radiance overhead and at the horizon,
//                                         blended by sqrt(elevation sine) (defaults blue, paler)
//         "ground": [r,g,b],              radiance below the horizon (default 0.03 grey)
//         "width": 512                    image width (height width / 2), 64..4096, even
//       },                                exactly one of "image" and "sky";
//       "intensity": 1, "rotation": [0,0,0,1] (environment-to-world),
//       "capture_width": 256              width of the copy written into the capture (height =
//                                         width / 2, box-filtered); 0 = not copied (then an env
//                                         camera must be given)
//     },
//     "virtual_objects": [                glTF 2.0 files (.glb or .gltf with embedded data)
//       {"gltf": "file.glb", "position", "rotation", "scale",
//        "velocity": [0,0,0] (m/s), "angular_velocity_deg": [0,0,0] (deg/s, axis * rate, world
//        axes, about the object's position)}   motion over the frames (scene.json gets frame 0)
//     ],
//     "depth_sensor": {...}               any field of DepthSensorSettings (sensors.h), by name
//     "env_camera": {                     optional fisheye environment camera (equidistant r = f theta)
//       "position", "look_at", "up",      its pose (OpenCV axes, looks along +z)
//       "size": 256, "fov_deg": 180, "spp": 16
//     }
//   }
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/reference/path_tracer.h"
#include "mrgi/reference/sensors.h"

namespace mrgi::reference {

struct CameraKeyframe {
  double time = 0.0;
  glm::dvec3 position{0.0}, look_at{0.0, 0.0, 1.0}, up{0.0, 1.0, 0.0};
};

enum class ShapeKind { Plane, Box, Sphere, Gltf };

struct RealObjectDesc {
  ShapeKind shape = ShapeKind::Plane;
  glm::dvec3 size{1.0};            // plane: x, z in .x, .y; box: x, y, z
  double radius = 0.5;             // sphere
  std::string gltf;                // absolute path (Gltf)
  glm::dvec3 position{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  double scale = 1.0;
  std::optional<RefMaterial> material;  // required for generated shapes
};

enum class LampKind { Point, Spot, Directional, Area };

struct LampDesc {
  LampKind type = LampKind::Point;
  bool real = true;
  glm::dvec3 position{0.0}, direction{0.0, -1.0, 0.0};
  glm::dvec3 color{1.0};
  double intensity = 1.0;
  double inner_angle_deg = 30.0, outer_angle_deg = 45.0;
  glm::dvec2 size{0.2, 0.2};       // area lamp edge lengths
};

// A procedural sun and sky (description "environment.sky").
struct ProceduralSky {
  glm::dvec3 sun_direction{0.0, 1.0, 0.0};  // unit, towards the sun, environment axes
  glm::dvec3 sun_irradiance{3.0};           // W/m^2 at normal incidence
  double sun_radius_deg = 2.0;
  glm::dvec3 zenith{0.05, 0.09, 0.20}, horizon{0.12, 0.15, 0.20}, ground{0.03};
  int width = 512;
};

// The equirectangular image of a procedural sky (mapping of path_tracer.h): sky radiance
// horizon + (zenith - horizon) sqrt(y) above the horizon, `ground` below, plus the sun disc,
// whose pixels (by pixel centre) are scaled so they carry exactly sun_irradiance.
ImageRGBF render_sky(const ProceduralSky& sky);

struct EnvironmentSourceDesc {
  bool present = false;
  std::string image;               // absolute path; empty when `sky` is given
  std::optional<ProceduralSky> sky;
  double intensity = 1.0;
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  int capture_width = 256;
};

struct VirtualObjectMotionDesc {
  std::string gltf;                // absolute path
  glm::dvec3 position{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  double scale = 1.0;
  glm::dvec3 velocity{0.0};
  glm::dvec3 angular_velocity_deg{0.0};
};

struct EnvCameraDesc {
  glm::dvec3 position{0.0}, look_at{0.0, 1.0, 0.0}, up{0.0, 0.0, 1.0};
  int size = 256;
  double fov_deg = 180.0;
  int spp = 16;
};

struct LightProbeDesc {
  int width = 64;   // equirectangular width (height = width / 2), 8..1024, even
  int spp = 256;
};

struct SceneDescription {
  std::string path;                // the file it came from
  int frames = 8;
  double fps = 30.0;
  Intrinsics intrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};
  double exposure = 1.0;
  CameraNoiseSettings noise;
  std::vector<CameraKeyframe> camera_path;
  int spp = 64, max_depth = 6, rr_depth = 3;
  uint64_t seed = 1;
  std::vector<RealObjectDesc> real_objects;
  std::vector<LampDesc> lights;
  EnvironmentSourceDesc environment;
  std::vector<VirtualObjectMotionDesc> virtual_objects;
  DepthSensorSettings depth;
  std::optional<EnvCameraDesc> env_camera;
  std::optional<LightProbeDesc> light_probe;
};

Expected<SceneDescription> load_scene_description(const std::string& path);

// Camera-to-world pose at time t (seconds), OpenCV axes; linear interpolation between keyframes.
Pose camera_pose_at(const SceneDescription& d, double t);
// Camera-to-world rotation of a camera at `position` looking at `look_at` with `up` (OpenCV axes).
glm::dquat look_rotation(const glm::dvec3& position, const glm::dvec3& look_at, const glm::dvec3& up);

}  // namespace mrgi::reference
