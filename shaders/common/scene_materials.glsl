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

#ifndef __cplusplus
// The diffuse albedo at texture coordinate uv: the base colour (factor x texture, where the
// material has one) x (1 - metallic) x (1 - transmission): what a metal reflects and what glass
// lets through is not reflected diffusely.
vec3 material_diffuse_albedo(GpuMaterial m, sampler2DArray base_color_maps, vec2 uv) {
  vec3 base = m.base_color_factor.rgb;
  if (m.params.z >= 0.0f) base *= textureLod(base_color_maps, vec3(uv, m.params.z), 0.0f).rgb;
  return base * (1.0f - m.params.x) * (1.0f - clamp(m.specular.w, 0.0f, 1.0f));
}
#endif

#ifdef __cplusplus
static_assert(sizeof(GpuMaterial) == 80, "std430 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_SCENE_MATERIALS_GLSL
