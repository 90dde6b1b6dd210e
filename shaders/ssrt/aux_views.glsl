// The ssrt technique's auxiliary orthographic geometry buffers (paper Sec. 5.1: "three additional
// buffers for the left, right and top parts of the scene" plus one "from the dominant light
// direction"), extracted from the TSDF volume by ssrt_tsdf_aux (technique/ssrt/volume.h).
// Compiled as GLSL (std140 uniform block) and as C++ (GLM): only vec4 / ivec4 / mat4 members.
//
// Layers of Volume::aux_position() (RGBA32F 2D array, 4 layers):
//   0 left   at the camera centre, looking along the camera's -x
//   1 right  at the camera centre, looking along the camera's +x
//   2 top    at the camera centre, looking along the camera's -y (OpenCV y points down)
//   3 light  from the dominant light, looking along -direction_to_light
// Texel: xyz = world position of the first front-facing surface along the texel's parallel
// ray, w = its depth along the view axis in metres (0 = no surface).
//
// Occlusion rule (what a consumer such as ssrt_transfer does for a world sample point y):
//   for i in [0, info.x):
//     p = world_to_aux[i] * vec4(y, 1)   // p.xy: fraction of the layer's used square, [0, 1]
//                                        // p.z:  y's depth along the layer's view axis, metres
//     if p.xy outside [0, 1] or p.z <= 0: layer i says nothing about y
//     texel = min(ivec2(p.xy * info.y), info.y - 1); w = texelFetch(layer i, texel).w
//     if w > 0 and w < p.z - bias: y lies behind layer i's first surface -> occluded
// (ssrt_aux_texel_at below does the second and third lines.) The used square of every layer is the
// corner [0, info.y)^2 of an allocation of info.z texels per side: sampler coordinates, where
// wanted, are p.xy * info.y / info.z.
#ifndef MRGI_SSRT_AUX_VIEWS_GLSL
#define MRGI_SSRT_AUX_VIEWS_GLSL

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::mat4;
using glm::vec4;
#endif

#define SSRT_AUX_LAYERS 4
#define SSRT_AUX_LEFT 0
#define SSRT_AUX_RIGHT 1
#define SSRT_AUX_TOP 2
#define SSRT_AUX_LIGHT 3

struct SsrtAuxViews {
  mat4 world_to_aux[SSRT_AUX_LAYERS];  // world -> (u, v in [0, 1], depth along the axis m, 1)
  mat4 aux_to_world[SSRT_AUX_LAYERS];  // the inverse: (u, v, depth, 1) -> world
  vec4 direction[SSRT_AUX_LAYERS];     // xyz world unit view axis (rays travel along it), w 0
  vec4 extent[SSRT_AUX_LAYERS];        // x, y side of the covered square m, z metres per texel,
                                       // w depth where the layer's rays leave the cube (m)
  ivec4 info;                          // x valid layers, y aux texels per side (used),
                                       // z texels per side allocated, w unused
};

#ifdef __cplusplus
static_assert(sizeof(SsrtAuxViews) == 8 * 64 + 8 * 16 + 16, "std140 mirror");
}  // namespace mrgi::shader
#else
// The texel of an aux layer (`texels` used per side) for a point whose layer coordinates are
// p = world_to_aux * (y, 1) (u, v, depth along the axis), and that depth; false when y projects
// outside the layer's square or lies behind its image plane. Takes the coordinates rather than
// the layer's matrix, so a caller can derive one layer's from another's (ssrt_transfer mirrors
// the left layer's into the right one's); never the whole SsrtAuxViews: a struct parameter
// indexed by a loop variable was copied into scratch memory on every call (the aux test was
// 55 % of ssrt_transfer on lavapipe).
bool ssrt_aux_texel_at(vec3 p, int texels, out ivec2 texel, out float depth) {
  texel = ivec2(0);
  depth = p.z;
  if (any(lessThan(p.xy, vec2(0.0f))) || any(greaterThan(p.xy, vec2(1.0f))) || !(p.z > 0.0f))
    return false;
  texel = min(ivec2(p.xy * float(texels)), ivec2(texels - 1));
  return true;
}
#endif

#endif  // MRGI_SSRT_AUX_VIEWS_GLSL
