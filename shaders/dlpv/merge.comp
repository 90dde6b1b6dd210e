#version 460
// dlpv: the merge of the DLPV paper's Algorithm 1 into the two solutions compose reads.
//   real pixel:    L_r  = albedo / pi (E_real_lamps(n) + E_ambient_r(n))   (the real scene as lit)
//                  L_rv = albedo / pi (E_lamps(n) + E_ambient_rv(n) + E_delta(p, n))  (V^Delta:
//                         bounce from the virtual objects, minus the light they block: shadow)
//   virtual pixel: L_rv = BRDF x E_lamps + albedo / pi (E_ambient_rv(n) + E_rho(p, n)) + emission
//                  (V^rho: bounce light from the real and virtual surfaces; without V^rho, at the
//                  cheaper levels, the virtual pixel's own shading: lamps and ambient)
// E_volume(p, n) = lpv_irradiance of the volume's accumulated intensity, trilinear at p (0 outside
// the volume). E_ambient_rv is less what the virtual objects hide of it (the direct-light block's
// environment occlusion, shading/environment_occlusion.h): the volume carries the lamps'
// antiradiance, not the environment's. Lamps are unshadowed here (Algorithm 1): a virtual object's shadow on the real
// scene is the volume's antiradiance (paper Sec. 4.3.2), and real shadows are in the camera image.
#extension GL_GOOGLE_include_directive : require
// The G-buffers are read as storage images: on lavapipe a sampled texelFetch costs 2-3x as much.
#include "shared/mrgi_shared.h"
#include "shared/lpv_math.h"
#include "gi/volume_lookup.glsl"
#include "common/frame_constants.glsl"
#include "common/light_set.glsl"
#include "common/surface_shading.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { LightSet light_set; };
AmbientIrradiance ambient_rv, ambient_r;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 5, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 8, rgba16f) readonly uniform image2D virtual_emission;
layout(set = 0, binding = 9) uniform sampler3D delta_r;
layout(set = 0, binding = 10) uniform sampler3D delta_g;
layout(set = 0, binding = 11) uniform sampler3D delta_b;
layout(set = 0, binding = 12) uniform sampler3D rho_r;
layout(set = 0, binding = 13) uniform sampler3D rho_g;
layout(set = 0, binding = 14) uniform sampler3D rho_b;
layout(set = 0, binding = 15, rgba16f) writeonly uniform image2D lit_rv;
layout(set = 0, binding = 16, rgba16f) writeonly uniform image2D lit_r;
layout(set = 0, binding = 17, rgba16f) readonly uniform image2D env_occlusion;
// occlusion.x: the environment occlusion's divisor (0: none this frame).
layout(push_constant) uniform Volume { VolumeConstants volume_block; ivec4 occlusion; };
#include "shading/env_occlusion_lookup.glsl"


void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  volume = volume_block;
  ambient_rv = light_set.ambient_rv;
  ambient_r = light_set.ambient_r;
  const int count = min(light_set.count.x, MRGI_MAX_LIGHTS);
  const ShadowLight lamp0 = light_set.lights[0], lamp1 = light_set.lights[1], lamp2 = light_set.lights[2],
                    lamp3 = light_set.lights[3], lamp4 = light_set.lights[4], lamp5 = light_set.lights[5],
                    lamp6 = light_set.lights[6], lamp7 = light_set.lights[7];
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  vec4 vpos = imageLoad(virtual_position, pixel);
  bool is_virtual = vpos.w > 0.5f;
  vec4 pos, nrm, alb;
  if (is_virtual) {
    pos = vpos;
    nrm = imageLoad(virtual_normal, pixel);
    alb = imageLoad(virtual_albedo, pixel);
  } else {
    pos = imageLoad(real_position, pixel);
    nrm = imageLoad(real_normal, pixel);
    alb = vec4(imageLoad(real_albedo, pixel).rgb, 0.0f);
    if (!(pos.w > 0.0f)) {  // no measurement: nothing is known there, both solutions are 0
      imageStore(lit_rv, pixel, vec4(0.0f));
      imageStore(lit_r, pixel, vec4(0.0f));
      return;
    }
  }
  vec3 p = pos.xyz;
  vec3 n = normalize(nrm.xyz);
  vec3 v = normalize(frame.camera_world.xyz - p);
  vec3 lamps = vec3(0.0f), real_lamps = vec3(0.0f);  // every lamp; the real ones (light L_r)
  // Spelled out over the 8 private copies (a loop indexing the uniform array gathered each
  // light's values lane by lane on lavapipe: MRGI_UNIFORM_COPIES).
#define MRGI_SHADE_LAMP(L, K) \
  if (K < count) { \
    vec3 wi; \
    vec3 e = light_incident(L, p, wi); \
    float nl = dot(n, wi); \
    if (nl > 0.0f) { \
      vec3 lo = brdf(n, v, wi, alb.rgb, alb.a, is_virtual ? nrm.w : 1.0f, is_virtual) * e * nl; \
      lamps += lo; \
      if (L.direction_real.w > 0.5f) real_lamps += lo; \
    } \
  }
  MRGI_SHADE_LAMP(lamp0, 0) MRGI_SHADE_LAMP(lamp1, 1) MRGI_SHADE_LAMP(lamp2, 2) MRGI_SHADE_LAMP(lamp3, 3)
  MRGI_SHADE_LAMP(lamp4, 4) MRGI_SHADE_LAMP(lamp5, 5) MRGI_SHADE_LAMP(lamp6, 6) MRGI_SHADE_LAMP(lamp7, 7)
#undef MRGI_SHADE_LAMP
  vec3 l_rv, l_r;
  if (is_virtual) {
    // With V^rho, not the residual ambient too (light_set.glsl count.y: it holds that bounce).
    bool rho = volume.extent.w > 0.5f;
    vec3 e = rho && light_set.count.y != 0 ? vec3(0.0f)
                                           : occluded_ambient(ambient_irradiance(ambient_rv, n), pixel, p, true, occlusion.x);
    if (rho) e += volume_irradiance(rho_r, rho_g, rho_b, p, n);
    l_rv = lamps + alb.rgb * max(e, vec3(0.0f)) * (1.0f / MRGI_PI) +
           (frame.flags.y != 0 ? imageLoad(virtual_emission, pixel).rgb : vec3(0.0f));
    l_r = vec3(0.0f);
  } else {
    l_r = real_lamps + alb.rgb * ambient_irradiance(ambient_r, n) * (1.0f / MRGI_PI);
    vec3 delta = volume.extent.z > 0.5f ? volume_irradiance(delta_r, delta_g, delta_b, p, n) : vec3(0.0f);
    vec3 e_ambient = occluded_ambient(ambient_irradiance(ambient_rv, n), pixel, p, false, occlusion.x);
    l_rv = lamps + alb.rgb * (e_ambient + delta) * (1.0f / MRGI_PI);
  }
  // Half floats end at 65504, and antiradiance can overshoot below 0: clamp.
  imageStore(lit_rv, pixel, vec4(clamp(sanitize(l_rv), vec3(0.0f), vec3(60000.0f)), 1.0f));
  imageStore(lit_r, pixel, vec4(clamp(sanitize(l_r), vec3(0.0f), vec3(60000.0f)), 1.0f));
}
