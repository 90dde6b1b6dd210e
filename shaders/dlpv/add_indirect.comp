#version 460
// dlpv with shadow-mapped direct light (the DLPV paper's Sec. 7 alternative, the levels whose
// DlpvLevel::antiradiance_shadows is off): baseline's shading pass has written both solutions with
// the lamps' shadows (real and virtual casters, DIR eq. 1-5); this pass adds the bounce light
//   real pixel:    L_rv += albedo / pi E_delta(p, n)   (V^Delta from the VPLs only: the virtual
//                  objects' bounce onto the real scene, minus the bounce they block)
//   virtual pixel: L_rv += albedo / pi E_rho(p, n)     (V^rho: bounce from everything; levels
//                  without V^rho add nothing)
// L_r is left as baseline wrote it (the real scene's own bounce is in the camera image).
#extension GL_GOOGLE_include_directive : require
// The G-buffers are read as storage images: on lavapipe a sampled texelFetch costs 2-3x as much.
#include "shared/mrgi_shared.h"
#include "shared/lpv_math.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 7) uniform sampler3D delta_r;
layout(set = 0, binding = 8) uniform sampler3D delta_g;
layout(set = 0, binding = 9) uniform sampler3D delta_b;
layout(set = 0, binding = 10) uniform sampler3D rho_r;
layout(set = 0, binding = 11) uniform sampler3D rho_g;
layout(set = 0, binding = 12) uniform sampler3D rho_b;
layout(set = 0, binding = 13, rgba16f) uniform image2D lit_rv;
// V^mu (DlpvAblation::two_volumes only; otherwise bound to V^Delta and not read).
layout(set = 0, binding = 14) uniform sampler3D mu_r;
layout(set = 0, binding = 15) uniform sampler3D mu_g;
layout(set = 0, binding = 16) uniform sampler3D mu_b;
struct VolumeConstants {
  vec4 grid;    // xyz: the volumes' min corner (m); w: cell size (m)
  vec4 extent;  // x: cells allocated per side; y: cells used; z: 1 = V^Delta present; w: 1 = V^rho
};
// rect: the internal pixels [x0, x1) x [y0, y1) the volume's box covers (technique/
// screen_bounds.h); nothing outside it receives light from the volume, so it is not dispatched.
// mode.x: 1 = the two-volume ablation, real pixels get E(V^rho) - E(V^mu) instead of E(V^Delta).
layout(push_constant) uniform Volume { VolumeConstants volume_block; ivec4 rect_block; ivec4 mode_block; };
VolumeConstants volume;

#include "dlpv/volume_lookup.glsl"

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  volume = volume_block;
  ivec2 pixel = rect_block.xy + ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, min(rect_block.zw, frame.internal_output_size.xy)))) return;
  vec4 vpos = imageLoad(virtual_position, pixel);
  bool is_virtual = vpos.w > 0.5f;
  vec3 add;
  if (is_virtual) {
    if (!(volume.extent.w > 0.5f)) return;
    vec3 n = normalize(imageLoad(virtual_normal, pixel).xyz);
    vec4 alb = imageLoad(virtual_albedo, pixel);
    add = alb.rgb * (1.0f - alb.a) * max(volume_irradiance(rho_r, rho_g, rho_b, vpos.xyz, n), vec3(0.0f));
  } else {
    vec4 pos = imageLoad(real_position, pixel);
    // Outside the volume before the normal and albedo are read: most of the rectangle's pixels.
    if (!(pos.w > 0.0f) || !(volume.extent.z > 0.5f) || !volume_contains(pos.xyz)) return;
    vec3 n = normalize(imageLoad(real_normal, pixel).xyz);
    vec3 e = mode_block.x == 1 ? volume_irradiance(rho_r, rho_g, rho_b, pos.xyz, n) - volume_irradiance(mu_r, mu_g, mu_b, pos.xyz, n)
                               : volume_irradiance(delta_r, delta_g, delta_b, pos.xyz, n);
    add = imageLoad(real_albedo, pixel).rgb * e;
  }
  vec4 lit = imageLoad(lit_rv, pixel);
  lit.rgb = clamp(lit.rgb + add * (1.0f / MRGI_PI), vec3(0.0f), vec3(60000.0f));
  imageStore(lit_rv, pixel, lit);
}
