// The light stage's lights with their shadow-map layers and its ambient, as the shading passes
// see them (one uniform buffer per frame slot, written each frame: environment regions and the
// probeless dominant light move). Shared by C++ and GLSL like frame_constants.glsl.
#ifndef MRGI_LIGHT_SET_GLSL
#define MRGI_LIGHT_SET_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::mat4;
using glm::vec4;
#endif

#define MRGI_MAX_LIGHTS 8
#define MRGI_LIGHT_POINT 0
#define MRGI_LIGHT_SPOT 1
#define MRGI_LIGHT_DIRECTIONAL 2

struct ShadowLight {
  vec4 position_type;   // xyz world position, metres (point, spot); w type (MRGI_LIGHT_*)
  vec4 direction_real;  // xyz unit direction the light travels (spot, directional); w 1 real lamp
  vec4 intensity;       // rgb W/sr (point, spot) or W/m^2 (directional), linear; w unused
  vec4 cone;            // x cos(inner half-angle), y cos(outer) (spot); z 2 tan(half fov) of the
                        // perspective maps (texel footprint per metre per texel count);
                        // w ortho map width in metres (directional)
  ivec4 layers;         // x first layer in shadow_primary (real casters of a real lamp, all
                        // casters of a virtual one); y first layer in shadow_virtual (virtual
                        // casters of a real lamp) or -1; z faces (1, or 6 for a point lamp cube)
};

// Ambient irradiance (the light not in `lights`, bands 0..2 of its SH, light/light_stage.h
// irradiance_matrices): E_c(n) = dot(vec4(n, 1), M_c * vec4(n, 1)) per channel. Three mat4s, not
// an array of nine SH coefficients, so a pass copies them whole on main's first line
// (MRGI_UNIFORM_COPIES) and evaluates them with two dot products each.
struct AmbientIrradiance {
  mat4 r, g, b;
};

// Point lamps use a cube of 6 perspective faces: +X, -X, +Y, -Y, +Z, -Z (major axis of the
// light-to-point vector picks the face), each a 90 degree frustum.
struct LightSet {
  // x number of lamps; y 1 when the ambient is the light stage's residual estimate (the real
  // light the declared lamps do not explain, light/light_stage.h residual_light): a technique
  // whose volume already carries the real scene's bounce to virtual surfaces (V^rho) leaves it
  // off them, since the residual holds that bounce too.
  ivec4 count;
  ShadowLight lights[MRGI_MAX_LIGHTS];
  mat4 face_view_proj[MRGI_MAX_LIGHTS * 6];      // lamp i face f at i * 6 + f; Vulkan clip
  AmbientIrradiance ambient_rv;                  // real + virtual ambient: lights L_rv
  AmbientIrradiance ambient_r;                   // real ambient: lights L_r (real surfaces)
};

#ifdef __cplusplus
static_assert(sizeof(ShadowLight) == 80, "std140 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_LIGHT_SET_GLSL
