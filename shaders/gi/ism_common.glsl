// Imperfect shadow maps (Ritschel et al. 2008; the DIR paper's visibility for VPLs, Sec. 3.3 and
// 4.3), shared by shaders/gi/ism_*.comp and the passes that look them up: one paraboloid map
// (shared/vpl_math.h) per VPL, laid out as square tiles of an atlas, `tiles_per_row` a row; two
// atlases, the real scene's points and the virtual objects' (the paper's two ISMs per VPL).
// A texel holds the distance (m) from the VPL to the nearest point splatted into it.
#ifndef MRGI_ISM_COMMON_GLSL
#define MRGI_ISM_COMMON_GLSL
#include "shared/vpl_math.h"

#define MRGI_ISM_EMPTY 0xffffffffu  // a splat texel no point reached
#define MRGI_ISM_NONE 1.0e30f       // a resolved texel with no surface: the VPL's light passes
#define MRGI_ISM_MAX_SPLAT_RADIUS 3 // texels each side of a splat's centre
#define MRGI_ISM_MIN_ELEVATION_COS 0.1f  // points below ~6 degrees over a VPL's plane splat nothing
// A pull-push parent is valid where this many of its four children are: 1 fills every hole
// within a 4 x 4 block of a splat, growing a silhouette by up to 3 texels (a virtual object's
// shadow dilated by a quarter of its size on a 64^2 map); 2 fills the holes of a sparse surface,
// which have valid neighbours, and grows a silhouette by about one.
#define MRGI_ISM_PULL_MIN_CHILDREN 2.0f

struct IsmParams {
  ivec4 tiles;   // x: VPL slots mapped; y: map side (texels); z: tiles per atlas row; w: points per VPL
  ivec4 source;  // real points: x, y the G-buffer's used size; virtual: x triangles, y draw ranges
  vec4 camera;   // real points: x fx, y fy of the G-buffer's pixels (for a point's footprint)
};

ivec2 ism_tile_origin(int vpl, int tiles_per_row, int side) {
  return ivec2(vpl % tiles_per_row, vpl / tiles_per_row) * side;
}

// The Halton point of point k of VPL j in [0, 1)^2: VPL j's points are the sequence's first ones
// (k = 0, 1, ...), shifted by a rotation of its own (Cranley-Patterson, from j's Halton point in
// bases 5 and 7), so each VPL's set is evenly spread and differs from the others'. (Taking every
// n-th point of one sequence instead fixes a digit of the bases that divide n: with 3 VPLs,
// every point of VPL 1 fell in one third of the image.)
vec2 ism_point_u(int k, int vpl) {
  uint h = uint(k) + 1u, r = uint(vpl) + 1u;
  return fract(vec2(halton(h, 2u), halton(h, 3u)) + vec2(halton(r, 5u), halton(r, 7u)));
}

// The map texel (in its tile) direction w from a VPL of normal n falls in; (-1, -1) outside the
// VPL's hemisphere.
ivec2 ism_texel(vec3 w, vec3 n, int side) {
  vec2 uv = paraboloid_uv(w, n);
  if (dot(uv, uv) > 1.0f) return ivec2(-1);
  return clamp(ivec2(floor((uv * 0.5f + 0.5f) * float(side))), ivec2(0), ivec2(side - 1));
}

// A directional VPL's map (MRGI_VPL_DIRECTIONAL, common/vpl.glsl): orthographic along the light,
// a square of 2 x half_side metres around `centre` across it (the tangent frame of the direction
// `towards` the light), holding each texel's nearest depth from a plane MRGI_ISM_ORTHO_REACH half
// sides towards the light (casters that far above the centre still shadow it, as gi/rsm.h's
// directional maps). The texel of p, (-1, -1) outside the square; `depth` p's own depth.
#define MRGI_ISM_ORTHO_REACH 4.0f
ivec2 ism_ortho_texel(vec3 p, vec3 centre, vec3 towards, float half_side, int side, out float depth) {
  vec3 d = p - centre;
  vec2 uv = vec2(dot(d, frame_tangent(towards)), dot(d, frame_bitangent(towards))) / half_side;
  depth = max(MRGI_ISM_ORTHO_REACH * half_side - dot(d, towards), 0.0f);
  if (any(greaterThan(abs(uv), vec2(1.0f)))) return ivec2(-1);
  return clamp(ivec2(floor((uv * 0.5f + 0.5f) * float(side))), ivec2(0), ivec2(side - 1));
}

#endif
