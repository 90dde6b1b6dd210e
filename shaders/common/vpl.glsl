// A virtual point light as the VPL buffer holds it (gi/vpl.h writes it, gi/ism.h and the dir
// shading read it), with the DIR paper's path flags (differential-instant-radiosity-reciprocal-
// shading.md Sec. 3.3-3.6). Shared by C++ and GLSL like frame_constants.glsl: vec4 members only.
#ifndef MRGI_VPL_GLSL
#define MRGI_VPL_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::vec4;
#endif

// Flag bits, stored in Vpl::position.w as a float (exact for these small integers).
#define MRGI_VPL_VALID 1      // the slot holds a VPL (0: empty, lights nothing)
#define MRGI_VPL_REAL_PATH 2  // r(x): its light path holds only real lamps and real surfaces (eq. 9-10)
#define MRGI_VPL_REAL_ONLY 4  // ir(VPL): lights real surfaces only, in L_r (VPL 3 of the paper's
                              // Fig. 6: a real surface a virtual object hides from the lamp)
#define MRGI_VPL_DIRECTIONAL 8  // a distant light: a region of the environment (the paper's
                                // environment VPLs, Sec. 3.7), fields as below

// A point VPL is a surface point, a cosine emitter with, on a glossy surface, a specular lobe
// (shared/vpl_math.h vpl_intensity); a directional one (MRGI_VPL_DIRECTIONAL) stands for light
// arriving from one direction, its shadow map orthographic (gi/ism_common.glsl).
struct Vpl {
  vec4 position;  // xyz world (m): the point; directional: the centre of its map. w: MRGI_VPL_* bits
  vec4 normal;    // xyz unit normal of its surface, on the side the light arrived from; w unused.
                  // Directional: xyz unit direction towards the light; w the map's half side (m)
  vec4 flux;      // rgb reflected flux of the cosine emitter (W), already divided by the
                  // probability of drawing it; directional: irradiance (W/m^2 at normal
                  // incidence). w unused
  vec4 lobe;      // xyz unit direction its light arrived from; w the lobe's roughness, < 0 none
                  // (a diffuse VPL: every real surface's, the paper's real specular is 0)
  vec4 specular;  // rgb Phi_in F0 (W), w Phi_in's luminance (W), as flux divided by the
                  // probability of drawing it (vpl_math.h vpl_glossy_split); 0 without a lobe.
                  // Directional: x its part j, y the parts n of its region (n <= 1: whole):
                  // on real pixels it shades the interleaving block's class j, times n (the
                  // parts stored region by region); virtual pixels take every part
};

#ifdef __cplusplus
static_assert(sizeof(Vpl) == 80, "std430 mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_VPL_GLSL
