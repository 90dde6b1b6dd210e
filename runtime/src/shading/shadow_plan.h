// Which shadow maps the scene's lamps need and the light-space matrices that render and read
// them (DIR section 3.3: a real lamp gets two maps, one with real and one with virtual casters;
// a virtual lamp one map with every caster). Pure CPU: at start-up for declared lamps, again
// whenever the light stage's lights move (environment regions, the probeless dominant light).
//
// Map shapes: spot lamp -> one perspective map (field of view = twice the outer cone angle,
// at most kMaxSpotFovDeg); point lamp -> a cube of 6 perspective 90-degree faces (not
// dual-paraboloid: straight edges rasterise exactly); directional lamp -> one orthographic map
// fitted around the virtual objects and real proxies (bounds enlarged by kOrthoMargin, at least
// kMinOrthoHalfWidth), since the shadows that change the output are near the virtual objects;
// outside that box the lamp is unshadowed in both solutions, so the differential is unaffected.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

// Relative to this file (not through the include path) so tests, which do not have shaders/ on
// their include path, can include this header too.
#include "common/light_set.glsl"
#include "mrgi/expected.h"
#include "mrgi/scene.h"
#include "frame/lod_view.h"

namespace mrgi::shading {

inline constexpr float kShadowNear = 0.05f;        // metres, perspective maps
inline constexpr float kShadowFar = 50.0f;         // metres
inline constexpr float kMaxSpotFovDeg = 160.0f;    // full angle
inline constexpr float kOrthoMargin = 2.0f;        // half-width = margin x bounds half-diagonal
inline constexpr float kMinOrthoHalfWidth = 1.0f;  // metres
inline constexpr float kOrthoDepth = 100.0f;       // metres, light placed half of it before

// One layer to render: which lamp and face, and which casters go into it.
struct ShadowFace {
  int light = 0;
  int face = 0;            // 0..5 for a point lamp's cube, else 0
  int layer = 0;           // layer in its map array
  glm::mat4 view_proj{1.0f};
  bool real_casters = false;     // the depth-camera grid mesh and the real proxies
  bool virtual_casters = false;  // the glTF virtual objects
  // The virtual meshes' level of detail for this face, for a map one texel wide: its focal_px
  // times the map's side is the focal length in texels (max_error_px left to the drawer).
  frame::LodView lod_per_texel;
};

struct ShadowPlan {
  shader::LightSet light_set{};          // what the shaders read (uniform buffer)
  std::vector<ShadowFace> primary;       // layers of shadow_primary
  std::vector<ShadowFace> virtual_only;  // layers of shadow_virtual (real lamps' virtual casters)
  int real_lamps = 0;
  int virtual_lamps = 0;
};

// Scene bounds the directional maps are fitted to (empty = none known: a box around the origin).
struct Bounds {
  glm::vec3 lo{0.0f}, hi{0.0f};
  bool empty = true;
  void add(const glm::vec3& a, const glm::vec3& b);
};

// BadInput (naming scene.json and the lamp index) for more than MRGI_MAX_LIGHTS lamps or a
// zero-length direction.
Expected<ShadowPlan> plan_shadow_maps(const SceneDesc& scene, const Bounds& bounds);
// The same for any list of lights (the light stage's, per frame), into `plan`, whose vectors
// keep their capacity (reserve once, re-plan without allocating). `where` prefixes messages.
Status plan_shadow_maps(const std::vector<LightDesc>& lights, const Bounds& bounds,
                        const std::string& where, ShadowPlan& plan);

// Cube face f (0..5 = +X, -X, +Y, -Y, +Z, -Z) as the shaders pick it from a light-to-point vector.
int cube_face_of(const glm::vec3& d);

}  // namespace mrgi::shading
