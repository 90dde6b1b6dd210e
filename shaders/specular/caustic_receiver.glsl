// The caustic receiver maps of the fast level (specular/caustics.h): per spot lamp with caustics,
// the irradiance its photons left on the surfaces they landed on, splatted once per photon trace
// into an octahedral map of the directions around the lamp (caustic_receiver.vert/.frag), and
// read by whatever lights a surface point (shading/direct_light.comp for the camera's pixels,
// specular/trace.comp for what mirrors and glass show) with caustic_receiver_lookup.glsl.
// Shared by C++ and GLSL: the lamps' block, vec4 members only.
#ifndef MRGI_SPECULAR_CAUSTIC_RECEIVER_GLSL
#define MRGI_SPECULAR_CAUSTIC_RECEIVER_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::vec4;
#endif

#define MRGI_CAUSTIC_RECEIVER_LAMPS 2  // specular/caustics.h Caustics::kMaxLamps
#define MRGI_CAUSTIC_RECEIVER_LEVELS 5  // mip 0 and four halvings (a pixel up to 16 texels wide)

struct CausticReceiverLamp {
  vec4 position;  // xyz the lamp (world, m); w the map's side (texels)
  vec4 frame_x;   // xyz the map's frame, rows of world -> map: z the lamp's axis (the map's pole),
  vec4 frame_y;   // so the octahedron's seams lie 90 degrees off the cone; w unused
  vec4 frame_z;
  ivec4 atlas;    // xy the map's first texel in the atlas; z its levels (mip 0 and z - 1 box-
                  // filtered halvings, caustic_receiver_origin); w unused
};

struct CausticReceivers {
  ivec4 count;  // x lamps with a map
  CausticReceiverLamp lamps[MRGI_CAUSTIC_RECEIVER_LAMPS];
};

// Where level k of a map of side `size` whose mip 0 starts at `origin` starts in the atlas: mip 0
// there, the halvings in a column to its right (mip 1 at the top, each next one below the last),
// so a lamp's map takes 1.5 size x size texels.
#ifdef __cplusplus
static_assert(sizeof(CausticReceiverLamp) == 80, "std430 mirror");
static_assert(sizeof(CausticReceivers) == 16 + 80 * MRGI_CAUSTIC_RECEIVER_LAMPS, "std430 mirror");
inline glm::ivec2 caustic_receiver_origin(glm::ivec2 origin, int size, int k) {
  return k == 0 ? origin : origin + glm::ivec2(size, size - (size >> (k - 1)));
}
}  // namespace mrgi::shader
#else
ivec2 caustic_receiver_origin(ivec2 origin, int size, int k) {
  return k == 0 ? origin : origin + ivec2(size, size - (size >> (k - 1)));
}

// Unit direction from lamp L to x in its map's frame.
vec3 caustic_receiver_direction(CausticReceiverLamp L, vec3 d) {
  return vec3(dot(L.frame_x.xyz, d), dot(L.frame_y.xyz, d), dot(L.frame_z.xyz, d));
}
#endif  // __cplusplus
#endif  // MRGI_SPECULAR_CAUSTIC_RECEIVER_GLSL
