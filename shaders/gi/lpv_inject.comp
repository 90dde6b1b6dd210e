#version 450
// Injection into a light propagation volume (gi/light_propagation.h; DLPV paper Sec. 4.3): one
// invocation per texel of a reflective shadow map, whose VPL (or, in direct mode, whose share of
// the lamp's light) is summed into its cell as 2-band SH of intensity, with float atomics.
//   indirect (paper eq. 12-13): I(w) = P / pi max(0, n . w), P the texel's reflected flux, at
//     the texel's position moved half a cell along its normal (no self-illumination, no VPL
//     behind its own surface);
//   indirect from real surfaces: the same for the texels of real surfaces only (position w 1;
//     virtual ones are 2): V^rho without a virtual object's light onto itself (an ablation);
//   direct (Sec. 4.3.2): the light arriving at the texel, P_in (W), as an emitter facing the
//     light's travel direction, moved half a cell towards the light; only where the other map
//     (`other_position`, R^rho for R^mu's texels) sees a different surface: the light the
//     virtual objects block, as antiradiance. Deviation: the paper injects R^rho's direct light
//     positively as well; a volume does not stop light at surfaces, so that light would flow on
//     through the object into the shadow below it and cancel it (and light from the side that
//     grazes past the real scene would add light nowhere blocked).
// `sign` is +1 for the map with the virtual object (R^rho) and -1 for the one without (R^mu):
// VPLs both maps see cancel, new ones add, blocked ones subtract (eq. 13).
//   delta pair (indirect): both maps in one pass, this one with `sign`, the other
//     (other_*) with -sign, and only where their positions differ: R^rho is R^mu's copy with the
//     virtual objects drawn over it (gi/rsm.h), so a texel both maps hold bit for bit would
//     cancel exactly; only the texels the virtual objects cover are injected.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
#include "shared/lpv_math.h"

layout(local_size_x = 8, local_size_y = 8) in;
// The mode, one pipeline each (on lavapipe a shader pays for all of its code, taken or not):
// 0 indirect, 1 direct, 2 indirect from real surfaces, 3 delta pair.
layout(constant_id = 0) const int kMode = 0;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D rsm_position;  // xyz world m, w 1 real, 2 virtual
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D rsm_normal;    // xyz world, unit
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D rsm_flux;      // rgb reflected W, a: incident W per unit light colour
layout(set = 0, binding = 3, r32f) uniform imageBuffer cells;                 // 12 per cell: channel * 4 + coefficient
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D other_position;  // direct, delta pair: the other map
layout(set = 0, binding = 5, rgba16f) uniform readonly image2D other_normal;    // delta pair
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D other_flux;      // delta pair
layout(push_constant) uniform InjectParams {
  vec4 grid;       // xyz: the volume's min corner (m); w: cell size (m)
  ivec4 sizes;     // x: cells per side; y, z: the map's used width and height
  vec4 light;      // xyz: direction the light travels (w 0) or the lamp's position (w 1)
  vec4 colour;     // rgb: the lamp's colour (direct mode); w: sign, +1 or -1
  vec4 options;    // x: VPL shift along the normal, cells (0.5; 0 only as an ablation)
} params_block;

vec4 grid;
ivec4 sizes;

// Sums `power` (per channel, signed) times `lobe` into the cell holding `at`.
void add_to_cell(vec3 at, vec4 lobe, vec3 power) {
  const ivec3 c = ivec3(floor((at - grid.xyz) / grid.w));
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(sizes.x)))) return;
  const int base = ((c.z * sizes.x + c.y) * sizes.x + c.x) * 12;
  for (int ch = 0; ch < 3; ++ch) {
    const float w = power[ch];
    if (w == 0.0) continue;
    imageAtomicAdd(cells, base + ch * 4 + 0, lobe.x * w);
    imageAtomicAdd(cells, base + ch * 4 + 1, lobe.y * w);
    imageAtomicAdd(cells, base + ch * 4 + 2, lobe.z * w);
    imageAtomicAdd(cells, base + ch * 4 + 3, lobe.w * w);
  }
}

// A texel's VPL (eq. 12) with `sign`: half a cell along its normal; none for a surface the light
// reaches from behind (it reflects nothing).
void add_vpl(vec4 pos, vec3 normal, vec3 flux, vec4 light, float shift, float sign) {
  const vec3 n = normalize(normal);
  const vec3 travel = light.w > 0.5 ? normalize(pos.xyz - light.xyz) : normalize(light.xyz);
  if (dot(n, travel) >= 0.0) return;
  add_to_cell(pos.xyz + n * (shift * grid.w), sh4_cosine_lobe(n) * (1.0 / MRGI_PI), flux * sign);
}

void main() {
  grid = params_block.grid;  // copied first: MRGI_UNIFORM_COPIES
  sizes = params_block.sizes;
  const vec4 light = params_block.light;
  const vec4 colour = params_block.colour;
  const vec4 options = params_block.options;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= sizes.y || p.y >= sizes.z) return;
  const vec4 pos = imageLoad(rsm_position, p);
  if (kMode == 3) {  // delta pair
    const vec4 other = imageLoad(other_position, p);
    if (other == pos) return;  // the same VPL in both maps
    if (pos.w > 0.5) add_vpl(pos, imageLoad(rsm_normal, p).xyz, imageLoad(rsm_flux, p).xyz, light, options.x, colour.w);
    if (other.w > 0.5)
      add_vpl(other, imageLoad(other_normal, p).xyz, imageLoad(other_flux, p).xyz, light, options.x, -colour.w);
    return;
  }
  if (pos.w < 0.5) return;
  if (kMode == 1) {
    const vec4 other = imageLoad(other_position, p);
    if (other.w > 0.5 && distance(other.xyz, pos.xyz) <= 0.25 * grid.w) return;  // not blocked
    const vec3 travel = light.w > 0.5 ? normalize(pos.xyz - light.xyz) : normalize(light.xyz);
    add_to_cell(pos.xyz - travel * (0.5 * grid.w), sh4_cosine_lobe(travel) * (1.0 / MRGI_PI),
                colour.xyz * imageLoad(rsm_flux, p).w * colour.w);
    return;
  }
  if (kMode == 2 && pos.w > 1.5) return;  // a virtual surface's VPL
  add_vpl(pos, imageLoad(rsm_normal, p).xyz, imageLoad(rsm_flux, p).xyz, light, options.x, colour.w);
}
