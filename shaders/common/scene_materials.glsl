// Virtual object materials as the GPU sees them (one std430 array, uploaded at start-up), shared
// by C++ and GLSL like frame_constants.glsl.
#ifndef MRGI_SCENE_MATERIALS_GLSL
#define MRGI_SCENE_MATERIALS_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::vec4;
#endif

struct GpuMaterial {
  vec4 base_color_factor;  // linear RGBA (glTF baseColorFactor)
  vec4 params;             // x metallic, y roughness, z base-colour texture layer (-1 none), w unused
  vec4 emission;           // rgb emitted radiance (glTF emissiveFactor x
                           // KHR_materials_emissive_strength), w its texture's layer (-1 none)
  vec4 specular;           // x shared/specular_math.h specular_kind, y ior, z attenuation
                           // distance (m, 0: none; KHR_materials_volume), w transmission
  vec4 attenuation;        // rgb attenuation colour (KHR_materials_volume), w unused
};

#ifdef __cplusplus
static_assert(sizeof(GpuMaterial) == 80, "std430 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_SCENE_MATERIALS_GLSL
