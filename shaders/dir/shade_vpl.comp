#version 460
// dir: the indirect light of the VPLs (gi/vpl.h) at every pixel, with the DIR paper's path flags
// (differential-instant-radiosity-reciprocal-shading.md eq. 6-8), so both solutions come out of
// one pass:
//   L_rv += L_o (1 - ir(VPL)) min(st_r, st_v)
//   L_r  += L_o r(path) r(p) st_r
// L_o = albedo / pi x the VPL's irradiance at p (shared/vpl_math.h vpl_irradiance; diffuse:
// the virtual surfaces' base colour x (1 - metallic)); with glossy VPLs (kGlossy: a scene with a
// glossy virtual material) the VPLs' specular lobes are in their irradiance
// (vpl_irradiance_rgb) and a virtual surface reflects it by its whole BRDF towards the camera
// (common/surface_shading.glsl brdf: the paper's potentially glossy D at both ends of the DD
// segment; real surfaces stay diffuse, the paper's real specular is 0); st_r, st_v: the VPL's real and virtual
// imperfect shadow maps (gi/ism.h), one tap each, with a bias that grows with the distance (an
// ISM is a sparse, splatted depth map).
// Interleaved sampling (the paper's 4x4 G-buffer split, Segovia et al. 2006): the pixel at
// (x, y) shades only the VPLs j = (x mod 4) + 4 (y mod 4) (mod 16), its sum scaled by 16, and
// merge_rows.comp and merge_columns.comp average the 16 neighbours of a 4x4 block
// geometry-aware. Written packed with the pixel's surface key (indirect_pack.glsl). The paper splits the
// G-buffer into 16 sub-images for a GPU's caches; on a CPU device the pixels of a block share
// them anyway, so mrgi interleaves in place.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/vpl_math.h"
#include "common/frame_constants.glsl"
#include "common/vpl.glsl"
#include "dir/dir_params.glsl"
#include "gi/indirect_pack.glsl"
#include "common/light_set.glsl"
#include "common/surface_shading.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_albedo;
layout(std430, set = 0, binding = 7) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 8, rg32f) readonly uniform image2D ism_distances;  // level 0: x real, y virtual
layout(set = 0, binding = 9, rgba32ui) writeonly uniform uimage2D indirect;  // indirect_pack.glsl
layout(push_constant) uniform Params { DirParams params_block; };
// Ablations (mrgi/research.h DirAblation), one pipeline each: bit 1 one shadow map (the nearest
// surface and its kind), bit 2 no ir(VPL) (real-only VPLs light nothing).
layout(constant_id = 0) const int kAblation = 0;
layout(constant_id = 1) const bool kGlossy = false;
const bool kGlossyLobes = kGlossy;  // gi/vpl_light.glsl
#include "gi/vpl_light.glsl"
const bool kOneShadowMap = (kAblation & 1) != 0;
const bool kNoRealOnly = (kAblation & 2) != 0;
DirParams params;

void main() {
  frame = frame_ubo; params = params_block;  // MRGI_UNIFORM_COPIES
  // One texel per `extent.z` x `extent.z` G-buffer pixels (the fast levels shade the indirect
  // light at half resolution; the direct-light block's shading pass up-samples it, geometry-aware).
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, params.extent.xy))) return;
  ivec2 pixel = min(texel * params.extent.z, frame.internal_output_size.xy - 1);
  vec4 vpos = imageLoad(virtual_position, pixel);
  bool is_virtual = vpos.w > 0.5f;
  vec4 pos, nrm;
  vec3 albedo;
  vec4 base = vec4(0.0f);  // a virtual surface's base colour and metallic (kGlossy)
  if (is_virtual) {
    pos = vpos;
    nrm = imageLoad(virtual_normal, pixel);
    base = imageLoad(virtual_albedo, pixel);
    albedo = base.rgb * (1.0f - base.a);
  } else {
    pos = imageLoad(real_position, pixel);
    nrm = imageLoad(real_normal, pixel);
    albedo = imageLoad(real_albedo, pixel).rgb;
  }
  vec3 l_rv = vec3(0.0f), l_r = vec3(0.0f);
  float nlen = length(nrm.xyz);
  bool surface = (is_virtual || pos.w > 0.0f) && nlen > 0.0f;
  vec3 n = surface ? nrm.xyz / nlen : vec3(0.0f, 0.0f, 1.0f);
  if (surface) {
    vec3 p = pos.xyz;
    vec3 view = normalize(frame.camera_world.xyz - p);
    bool glossy_receiver = kGlossy && is_virtual;
    int count = params.vpls.x, side = params.vpls.y, row = params.vpls.z, step = params.vpls.w * params.vpls.w;
    int first = params.vpls.w > 1 ? (texel.x % params.vpls.w) + params.vpls.w * (texel.y % params.vpls.w) : 0;
    // The lamps' and the bounce's VPLs interleaved, each standing for `step` (the merge
    // averages the block); the environment's (slots [extent.w, count): the direct light of the
    // environment, the dominant term where it shines) at every pixel, each for itself, or,
    // a region split into parts, each part at its class of the block for all of them.
    int environment = min(params.extent.w, count);
    for (int k = 0; k < 2; ++k) {
      int begin = k == 0 ? first : environment, end = k == 0 ? environment : count, stride = k == 0 ? step : 1;
      if (k == 1 && environment < count) {
        // The regions split into parts (common/vpl.glsl; every region alike, region-major):
        // a real pixel takes its class's part of each, for all of them.
        int parts = max(int(vpls[environment].specular.y), 1);
        if (parts > 1 && !is_virtual) {
          begin = environment + first % parts;
          stride = parts;
        }
      }
      float weight = float(stride);
      for (int j = begin; j < end; j += stride) {
        Vpl v = vpls[j];
        int flags = int(v.position.w);
        if ((flags & MRGI_VPL_VALID) == 0) continue;
        bool real_only = (flags & MRGI_VPL_REAL_ONLY) != 0;
        if (real_only && (is_virtual || kNoRealOnly)) continue;  // ir(VPL): real surfaces only
        // The real surfaces' bounce is already in the ambient's lower hemisphere (params.lighting.w).
        if (is_virtual && params.lighting.w > 0.5f && (flags & (MRGI_VPL_REAL_PATH | MRGI_VPL_DIRECTIONAL)) == MRGI_VPL_REAL_PATH)
          continue;
        vec3 e = vpl_incident(v, p, n, params.lighting.x);
        if (!any(greaterThan(e, vec3(0.0f)))) continue;
        vec2 stored;
        vec2 st = vpl_visibility(v, j, p, n, side, row, params.lighting.y, params.lighting.z, stored);
        float st_r = st.x, st_v = st.y;
        if (kOneShadowMap) {  // one map: only the nearest blocker is known, and its kind
          bool real_nearest = stored.x <= stored.y;
          st_r = real_nearest ? st_r : 1.0f;
          st_v = real_nearest ? 1.0f : st_v;
        }
        vec3 l_o = glossy_receiver ? brdf(n, view, vpl_direction(v, p), base.rgb, base.a, max(nrm.w, MRGI_VPL_MIN_ROUGHNESS), true) * e
                                   : albedo * (1.0f / MRGI_PI) * e;
        bool real_path = (flags & MRGI_VPL_REAL_PATH) != 0;
        if ((flags & MRGI_VPL_DIRECTIONAL) != 0) {
          // An environment region whose light the direct-light block adds unshadowed (its SH
          // ambient): only what the VPL's maps take away. Real pixels: the paper's difference
          // L_rv - L_r of this VPL, L_o (min(st_r, st_v) - st_r), into L_rv (L_r keeps the direct-light block's
          // smooth level, the denominator of the composite; the sparse real ISM's self-shadowing
          // of real surfaces would make it noisy and cancels in the difference anyway); virtual
          // pixels: L_o (min(st_r, st_v) - 1), so L_rv holds the region's light times its
          // visibility, as the paper's.
          if (is_virtual) l_rv += weight * l_o * (min(st_r, st_v) - 1.0f);
          else if (real_path) l_rv += weight * l_o * (min(st_r, st_v) - st_r);
          continue;
        }
        if (!real_only) l_rv += weight * l_o * min(st_r, st_v);                          // eq. 6, 8
        if (!is_virtual && real_path) l_r += weight * l_o * st_r;                         // eq. 7
      }
    }
  }
  float camera_distance = surface ? max(distance(pos.xyz, frame.camera_world.xyz), 1e-3f) : 0.0f;
  // L_rv may be negative (an environment region's occlusion, taken from the direct-light block's ambient).
  uvec4 packed_value = pack_indirect(clamp(l_rv, vec3(-60000.0f), vec3(60000.0f)), clamp(l_r, vec3(0.0f), vec3(60000.0f)), n,
                                     camera_distance, is_virtual);
  if (!surface) packed_value.w = 0u;
  imageStore(indirect, texel, packed_value);
}
