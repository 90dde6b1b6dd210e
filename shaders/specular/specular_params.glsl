// The specular stage's per-frame constants (runtime/src/specular/specular.h), shared by C++ and
// GLSL like frame_constants.glsl.
#ifndef MRGI_SPECULAR_PARAMS_GLSL
#define MRGI_SPECULAR_PARAMS_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::vec4;
#endif

#define MRGI_SPECULAR_MAX_SETS 4

// One impostor set: the cube of six faces drawn from `centre` around one object (or, at the
// cheaper levels, around every specular object together), laid out 3 x 2 faces in the atlas.
struct SpecularSet {
  vec4 centre;  // xyz world (m); w the radius of the objects it stands for (m)
  ivec4 atlas;  // xy the set's first texel in the atlas; z face size (texels); w unused
};

struct SpecularConstants {
  ivec4 counts;  // x sets, y linear search steps along a ray, z secant refinements, w search
                 // steps through the back faces (refraction's exit point)
  vec4 params;   // x depth validity tolerance (fraction of the depth), y compose eps (linear
                 // camera units), z compose alpha_max, w 1: back-projection on (0: ablation)
  vec4 shadow;   // the direct-light block's LevelConstants::shadow for the direct light's maps
  ivec4 flags;   // x 1: lamps lit with shadow maps; y 1: depth validity test on (0: ablation);
                 // z the environment grid's width in cells (EnvGrid, height z / 2; 0: none, the
                 // environment is env_sh); w 1: the caustic buffer holds this frame's caustics, 2: the
                 // receiver maps do (caustic_receiver.glsl), 0: none
  vec4 level;    // x photon-map texels per side of each glass-reflected photon
                 // (SpecularLevel::glass_reflection_stride); y the smallest Fresnel factor of a
                 // reflection off glass that is traced (SpecularLevel::glass_reflection_fresnel);
                 // zw unused
  ivec4 back_rect;  // xy the first pixel, zw one past the last of the back faces' buffers drawn
                    // this frame (the objects' projected boxes); outside, the buffers are stale
  vec4 env_sh[16];  // rgb: the environment's radiance, SH bands 0..3 (shared/mrgi_shared.h basis)
  SpecularSet sets[MRGI_SPECULAR_MAX_SETS];
};

#ifdef __cplusplus
static_assert(sizeof(SpecularSet) == 32, "std140 mirror");
static_assert(sizeof(SpecularConstants) == 6 * 16 + 16 * 16 + MRGI_SPECULAR_MAX_SETS * 32, "std140 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_SPECULAR_PARAMS_GLSL
