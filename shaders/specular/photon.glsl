// A caustic photon (specular/caustics.h), as photons.comp writes it and the caustic splat and
// dir's VPL sampling (gi/vpl_sample.comp) read it. Shared by C++ and GLSL: vec4 members only.
#ifndef MRGI_SPECULAR_PHOTON_GLSL
#define MRGI_SPECULAR_PHOTON_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::vec4;
#endif

struct Photon {
  vec4 position;  // xyz world, where it landed; w 0 nowhere, 1 on a real surface, 2 on a virtual one
  vec4 flux;      // rgb W it carries; w the lamp's light its texel stands for, per unit of the
                  // lamp's colour (W / (W/sr)): flux / (colour x w) is the path's Fresnel and
                  // transmittance weight
  vec4 normal;    // xyz unit normal of the surface it landed on, facing where it came from; w
                  // photon-map texels per side between photons of its kind (1, or the glass
                  // reflection stride)
  vec4 albedo;    // rgb that surface's diffuse albedo (the impostor's); w its footprint: the
                  // distance (m) to where its neighbours of its kind landed (photon_footprint.comp)
  vec4 origin;    // xyz its texel's point on the mirror or glass; w 1 (0: the texel saw none)
};

#ifdef __cplusplus
static_assert(sizeof(Photon) == 80, "std430 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_SPECULAR_PHOTON_GLSL
