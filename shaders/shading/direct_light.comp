#version 460
// The direct-light block (runtime/src/shading/direct_light.h): direct light with real/virtual
// shadow maps, per DIR eq. 1-5:
//   L_rv += L_o * min(st_r, st_v)          (every lamp, every surface)
//   L_r  += L_o * r(lamp) * r(p) * st_r    (only real lamps on real points, real casters)
// L_o: Lambert for real surfaces (albedo from the camera, recon/depth_to_positions.comp);
// Lambert + GGX (metallic/roughness) for virtual ones; inverse-square distance, spot cone.
// The lights are the light stage's (light/light_stage.h): declared lamps, an environment's
// strongest median-cut regions or the probeless dominant light, each with its shadow maps, so
// a virtual object occludes the sky's bright part for the real surface below it. The rest of
// the light is an ambient irradiance in SH (bands 0..2), unshadowed: the real part lights both
// solutions, a virtual environment L_rv only; in L_rv it loses what the virtual objects hide of
// it (kEnvOcclusion, shading/environment_occlusion.h).
// Plus the technique's indirect light, by the encoding its input declares (kIndirect):
//   1 screen (ScreenIndirect): packed radiance pairs (gi/indirect_pack.glsl) into both
//     solutions, L_rv += indirect_rv, L_r += indirect_r, up-sampled from its resolution
//     (indirect_params.y G-buffer pixels a texel) by bilinear weights times the surface test
//     (plain bilinear where no neighbour is on the pixel's surface);
//   2 volumes (VolumeIndirect): SH irradiance volumes into L_rv only (the real scene's own
//     bounce is in the camera image):
//       real pixel:    L_rv += albedo / pi E_real(p, n), E_real = E(real volume), or
//                      E(real) - E(subtract) with kVolumeDifference
//       virtual pixel: L_rv += albedo / pi E(virtual volume)   (kVolumeVirtual)
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/lpv_math.h"
#include "gi/volume_lookup.glsl"
#include "common/frame_constants.glsl"
#include "common/light_set.glsl"
#include "common/surface_shading.glsl"
#include "gi/indirect_pack.glsl"
#include "shared/specular_math.h"
#include "specular/caustic_receiver.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { LightSet light_set; };
AmbientIrradiance ambient_rv, ambient_r;  // private copies of light_set's (MRGI_UNIFORM_COPIES)
// The G-buffers are read as storage images: on lavapipe a sampled texelFetch costs 2-3x as much.
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 5, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 12, rgba16f) readonly uniform image2D virtual_emission;  // rgb emitted radiance
layout(set = 0, binding = 8) uniform sampler2DArrayShadow shadow_primary;
layout(set = 0, binding = 9) uniform sampler2DArrayShadow shadow_virtual;
layout(set = 0, binding = 10, rgba16f) writeonly uniform image2D lit_rv;
layout(set = 0, binding = 11, rgba16f) writeonly uniform image2D lit_r;
// Specialisation constants, not push constants: on lavapipe a shader pays for all of its code,
// taken or not (compose.comp), so each encoding, and a volume input without a virtual volume or
// the difference, compiles the rest out.
layout(constant_id = 0) const int kIndirect = 0;  // 0 none, 1 screen, 2 volumes
layout(constant_id = 3) const bool kVolumeDifference = false;
layout(constant_id = 4) const bool kVolumeVirtual = false;
const bool kScreenIndirect = kIndirect == 1;
const bool kVolumeIndirect = kIndirect == 2;
// The volume input (kVolumeIndirect; otherwise stand-ins are bound and never read).
layout(set = 0, binding = 13) uniform sampler3D real_volume_r;
layout(set = 0, binding = 14) uniform sampler3D real_volume_g;
layout(set = 0, binding = 15) uniform sampler3D real_volume_b;
layout(set = 0, binding = 16) uniform sampler3D virtual_volume_r;
layout(set = 0, binding = 17) uniform sampler3D virtual_volume_g;
layout(set = 0, binding = 18) uniform sampler3D virtual_volume_b;
layout(set = 0, binding = 19) uniform sampler3D subtract_volume_r;  // kVolumeDifference only
layout(set = 0, binding = 20) uniform sampler3D subtract_volume_g;
layout(set = 0, binding = 21) uniform sampler3D subtract_volume_b;
layout(set = 0, binding = 22, rgba32ui) readonly uniform uimage2D screen_indirect;  // kScreenIndirect only
// kOneShadowMap (DirectLightOptions::one_shadow_map: the dir ablation of mrgi/research.h): a real lamp's two
// maps read as the one map of Knecht et al. 2010 (the paper's [4]) would hold them: the nearer
// caster and its kind (the maps' depths, nearest texel), so a real caster behind a virtual one
// no longer shadows L_r (the double shadow of the paper's Fig. 5). The depths are read through
// a plain sampler beside the compare ones.
layout(constant_id = 1) const bool kOneShadowMap = false;
layout(set = 0, binding = 23) uniform sampler2DArray shadow_primary_depth;
layout(set = 0, binding = 24) uniform sampler2DArray shadow_virtual_depth;
// kCausticReceivers (the specular stage's fast level, frame/frame_resources.h CausticPhotons::receivers):
// the spot lamps' caustics through mirrors and glass, read from their receiver maps, added to
// L_rv on the diffuse pixels as albedo / pi x E (caustics-DIR paper eq. 12-14: never L_r, the
// light went through a virtual object); mirror and glass pixels get nothing (the stage's trace
// writes them, reading the maps for what they show).
layout(constant_id = 2) const bool kCausticReceivers = false;
layout(set = 0, binding = 25, rgba32f) readonly uniform image2D caustic_receivers;
layout(std430, set = 0, binding = 26) readonly buffer CausticReceiverLamps { CausticReceivers receiver_set; };
#include "specular/caustic_receiver_lookup.glsl"
// kEnvOcclusion (the block's environment occlusion, shading/environment_occlusion.h): the
// irradiance the virtual objects hide of the ambient, one texel per indirect_params.z internal
// pixels (0: none this frame), taken off the ambient of L_rv (never L_r: the camera already
// shows the real scene's own occlusion).
layout(constant_id = 5) const bool kEnvOcclusion = false;
layout(set = 0, binding = 27, rgba16f) readonly uniform image2D env_occlusion;
// kRealOnly: dispatched where no virtual pixel can be (outside the objects' projected bounds,
// frame::FrameInfo::virtual_area): every pixel is real, so the virtual G-buffer is not read and
// the virtual surfaces' code (GGX, emission, the virtual volume) compiles out. On lavapipe a
// shader runs all of its code for every pixel, taken or not: this variant is what real pixels
// cost (desk_spot lowest: a fifth less).
layout(constant_id = 6) const bool kRealOnly = false;
struct LevelConstants {
  vec4 shadow;  // x used map size / allocated size, y used size (texels), z allocated size,
                // w PCF radius (taps each side of the centre)
};
// indirect_params.y: the screen input's divisor (G-buffer pixels per texel side); z: the
// environment occlusion's (0: none this frame). rect: the pixels of this dispatch, [x0, x1) x
// [y0, y1) (a dispatch covers part of the image: the objects' bounds, or a band around them).
layout(push_constant) uniform Level { LevelConstants level_block; VolumeConstants volume_block; ivec4 indirect_params; ivec4 rect; };
LevelConstants level;


#include "common/shadowed_lamps.glsl"

#include "shading/env_occlusion_lookup.glsl"

void main() {
  frame = frame_ubo; level = level_block;  // MRGI_UNIFORM_COPIES
  if (kCausticReceivers) cache_caustic_receivers();
  if (kVolumeIndirect) volume = volume_block;
  ambient_rv = light_set.ambient_rv;
  ambient_r = light_set.ambient_r;
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy) + rect.xy;
  if (any(greaterThanEqual(pixel, min(frame.internal_output_size.xy, rect.zw)))) return;
  vec4 vpos = kRealOnly ? vec4(0.0f) : imageLoad(virtual_position, pixel);
  bool is_virtual = !kRealOnly && vpos.w > 0.5f;
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
  float roughness = is_virtual ? nrm.w : 1.0f;
  float r_p = is_virtual ? 0.0f : 1.0f;

  // A virtual surface's own emission (glTF emissive) is seen directly; what it lights is the
  // indirect input's.
  // With a virtual volume on virtual pixels, not the residual ambient too (light_set.glsl count.y).
  bool ambient_here = !(kVolumeVirtual && is_virtual && light_set.count.y != 0);
  vec3 e_ambient = ambient_here ? ambient_irradiance(ambient_rv, n) : vec3(0.0f);
  if (kEnvOcclusion && ambient_here) e_ambient = occluded_ambient(e_ambient, pixel, p, is_virtual, indirect_params.z);
  vec3 l_rv = alb.rgb * e_ambient * (1.0f / MRGI_PI) +
              (is_virtual && frame.flags.y != 0 ? imageLoad(virtual_emission, pixel).rgb : vec3(0.0f));
  vec3 l_r = r_p * alb.rgb * ambient_irradiance(ambient_r, n) * (1.0f / MRGI_PI);
  add_shadowed_lamps(p, n, v, alb.rgb, alb.a, roughness, is_virtual, r_p, level.shadow, kOneShadowMap, l_rv, l_r);
  if (kVolumeIndirect) {
    if (is_virtual) {
      if (kVolumeVirtual && volume.extent.w > 0.5f)
        l_rv += alb.rgb * (1.0f - alb.a) *
                max(volume_irradiance(virtual_volume_r, virtual_volume_g, virtual_volume_b, p, n), vec3(0.0f)) *
                (1.0f / MRGI_PI);
    } else if (volume.extent.z > 0.5f && volume_contains(p)) {
      vec3 e = volume_irradiance(real_volume_r, real_volume_g, real_volume_b, p, n);
      if (kVolumeDifference) e -= volume_irradiance(subtract_volume_r, subtract_volume_g, subtract_volume_b, p, n);
      l_rv += alb.rgb * e * (1.0f / MRGI_PI);
    }
  }
  if (kScreenIndirect) {
    int d = max(indirect_params.y, 1);
    uint key = pack_indirect(vec3(0.0f), vec3(0.0f), n, max(distance(p, frame.camera_world.xyz), 1e-3f), is_virtual).w;
    ivec2 low = (frame.internal_output_size.xy + d - 1) / d;
    vec2 f = (vec2(pixel) + 0.5f) / float(d) - 0.5f;
    ivec2 i0 = ivec2(floor(f));
    vec2 t = f - vec2(i0);
    vec3 sum_rv = vec3(0.0f), sum_r = vec3(0.0f), any_rv = vec3(0.0f), any_r = vec3(0.0f);
    float w_sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      ivec2 o = ivec2(k & 1, k >> 1);
      uvec4 tap = imageLoad(screen_indirect, clamp(i0 + o, ivec2(0), low - 1));
      float w = (o.x == 1 ? t.x : 1.0f - t.x) * (o.y == 1 ? t.y : 1.0f - t.y);
      vec3 rv = unpack_indirect_rv(tap), r = unpack_indirect_r(tap);
      any_rv += w * rv;
      any_r += w * r;
      if (same_surface(key, tap.w)) {
        sum_rv += w * rv;
        sum_r += w * r;
        w_sum += w;
      }
    }
    bool matched = w_sum > 1e-6f;
    l_rv += matched ? sum_rv / w_sum : any_rv;
    l_r += r_p * (matched ? sum_r / w_sum : any_r);
  }
  if (kCausticReceivers && !(is_virtual && pos.w > 1.5f)) {
    vec3 to_camera = p - frame.camera_world.xyz;  // the pixel's width there: distance / focal length
    float footprint_sq = dot(to_camera, to_camera) / (frame.internal_k.x * frame.internal_k.x);
    l_rv += alb.rgb * (1.0f - alb.a) * caustic_receiver_irradiance(p, footprint_sq) * (1.0f / MRGI_PI);
  }
  // Half floats end at 65504: clamp so no Inf reaches compose.
  imageStore(lit_rv, pixel, vec4(clamp(sanitize(l_rv), vec3(0.0f), vec3(60000.0f)), 1.0f));
  imageStore(lit_r, pixel, vec4(clamp(sanitize(l_r), vec3(0.0f), vec3(60000.0f)), 1.0f));
}
