#version 450
// The finest level of a map pair's importance pyramid (gi/vpl.h): per texel of the pair, the
// importance of drawing a VPL there from each of the DIR paper's two maps (Sec. 3.7), and
// whether the map covers it (the paper splits the VPL slots between the maps by covered texels):
//   x: the real map's VPL: the luminance of R^mu's reflected flux where R^mu holds a surface;
//      for a virtual lamp (one map with all casters, Sec. 3.7) every texel of R^rho, and no y;
//   y: the virtual map's VPL: the luminance of R^rho's reflected flux where R^rho holds a virtual
//      surface (R^rho is R^mu with the virtual objects drawn over it, gi/rsm.h: its virtual
//      texels are the virtual surfaces the lamp reaches, the others R^mu's bit for bit);
//   z, w: 1 where x, y count as covered.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D rho_position;  // w 1 real, 2 virtual, 0 none
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D rho_flux;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D mu_position;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D mu_flux;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D importance;   // level 0 of the pyramid
layout(push_constant) uniform Params {
  ivec4 size;  // x: the maps' used side (texels); y: 1 real lamp, 0 virtual
} params;

float luminance_of(vec3 c) { return max(dot(c, vec3(0.2126f, 0.7152f, 0.0722f)), 0.0f); }

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  int side = params.size.x;
  if (any(greaterThanEqual(t, ivec2(side)))) return;
  vec4 rp = imageLoad(rho_position, t);
  bool virtual_front = rp.w > 1.5f;
  vec4 out_value = vec4(0.0f);
  if (params.size.y != 0) {
    vec4 mp = imageLoad(mu_position, t);
    if (mp.w > 0.5f) out_value.xz = vec2(luminance_of(imageLoad(mu_flux, t).rgb), 1.0f);
    if (virtual_front) out_value.yw = vec2(luminance_of(imageLoad(rho_flux, t).rgb), 1.0f);
  } else if (rp.w > 0.5f) {
    out_value.xz = vec2(luminance_of(imageLoad(rho_flux, t).rgb), 1.0f);
  }
  // A NaN or Inf flux must not poison every sum above it.
  if (!(out_value.x < 3.0e38f)) out_value.x = 0.0f;
  if (!(out_value.y < 3.0e38f)) out_value.y = 0.0f;
  imageStore(importance, t, out_value);
}
