#version 460
// Reflective and refractive virtual objects in DIR (Knecht et al. 2013, Sec. 4.1 and 5.1), at the
// internal resolution over the pixels whose virtual material is specular (virtual_position.w >=
// 2: 2 + its material index, gbuffer/virtual.frag), as trace_list.comp listed them: a pass over
// the glass pixels whose reflection is traced (kRefractive, kReflect), one over the mirrors'
// (kReflect), one over the glass pixels whose reflection shows L_env (kRefractive), each compiled
// without the paths it never takes:
//   1. GBuf_refl: the mirror direction's ray searched against the set's impostors (a linear
//      search along the ray, then secant refinement: the iterative refinement of Popescu et al.
//      2006 on distance impostors);
//      GBuf_refr: two-sided refraction (Wyman 2005): Snell at the front face, the exit point found
//      along the refracted ray in the back faces' buffer (a search instead of Wyman's
//      interpolated distance estimate: exact where the buffer holds the exit, and no per-vertex
//      precomputation), Snell at the back face, then the impostor search as for the reflection.
//      The G-buffers are this pass's registers: each hit is shaded where it is found (its
//      position, normal, albedo and real/virtual flag are what Sec. 5.1 stores).
//   2. L'_rv and L'_r (eq. 3-5): a hit on a surface the camera sees takes the technique's solution
//      there (lamps, shadows and indirect light: dir's VPLs); one it does not see is lit by the
//      lamps with the direct-light block's shadow-map pair (a real lamp's light on a real hit in L'_r too,
//      common/shadowed_lamps.glsl) and the SH ambient; in L'_rv, the spot lamps' caustics on
//      it (in the solution, or caustic_at); times the Fresnel factors and the transmittance
//      colour (eq. 9).
//   3. Back-projection (eq. 6-11, Sec. 4.1.3): a real hit seen by the camera (inside the view,
//      its depth within the tolerance of the real G-buffer's there) takes the camera's colour;
//      the rendered light where the test fails or the hit is outside the view; the environment
//      (L_env) where a ray meets nothing modelled; composited by shared/specular_math.h
//      specular_compose. The result is written to lit_rv as radiance (compose shows a virtual
//      pixel's TM(L_rv)), lit_r 0.
// Virtual hits are lit as Lambertian surfaces of their base colour (the impostors keep no
// metallic or roughness), and a specular object seen in another's impostor is its base colour:
// the paper's one reflection or refraction per path (its Sec. 6).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/frame_constants.glsl"
#include "common/light_set.glsl"
#include "common/scene_materials.glsl"
#include "common/surface_shading.glsl"
#include "specular/specular_params.glsl"
#include "specular/caustic_receiver.glsl"

layout(local_size_x = 64) in;
// kRefractive: glass pixels (refraction); kReflect: the reflection traced (else L_env: glass whose
// Fresnel factor is below SpecularLevel::glass_reflection_fresnel).
layout(constant_id = 0) const bool kRefractive = false;
layout(constant_id = 1) const bool kReflect = true;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { LightSet light_set; };
layout(std140, set = 0, binding = 2) uniform SpecularUbo { SpecularConstants specular; };
layout(std430, set = 0, binding = 3) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 5, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 8, rgba32f) readonly uniform image2D back_position;
layout(set = 0, binding = 9, rgba16f) readonly uniform image2D back_normal;
layout(set = 0, binding = 10, rgba32f) readonly uniform image2D impostor_position;
layout(set = 0, binding = 11, rgba8_snorm) readonly uniform image2D impostor_normal;
layout(set = 0, binding = 12, rgba8) readonly uniform image2D impostor_albedo;
layout(set = 0, binding = 13) uniform sampler2DArrayShadow shadow_primary;
layout(set = 0, binding = 14) uniform sampler2DArrayShadow shadow_virtual;
layout(set = 0, binding = 15) uniform sampler2DArray shadow_primary_depth;  // one-map ablation only
layout(set = 0, binding = 16) uniform sampler2DArray shadow_virtual_depth;
layout(set = 0, binding = 17, r32ui) readonly uniform uimageBuffer color_words;
// The technique's solutions: read where a hit is a surface the camera sees (solution_at), written
// at the specular pixels (never read here: a hit is not on a mirror or glass pixel).
layout(set = 0, binding = 18, rgba16f) uniform image2D lit_rv;
layout(set = 0, binding = 19, rgba16f) uniform image2D lit_r;
// The light stage's environment grid (light/env_sampler.h: world-space equirectangular cells
// of filtered radiance, u = 0.5 + atan2(x, -z) / 2 pi, v = acos(y) / pi), flags.z cells wide.
layout(std430, set = 0, binding = 20) readonly buffer EnvGrid { vec4 env_cells[]; };
#include "common/env_grid.glsl"
// The spot lamps' caustics on the surfaces the camera sees (caustics.h; flags.w 1 when written
// this frame): rgb irradiance.
layout(set = 0, binding = 21, rgba16f) readonly uniform image2D caustics;
// The fast level's caustic receiver maps (caustic_receiver.glsl; flags.w 2: the technique's
// shading added them to what the camera sees, and the hits here read them too).
layout(set = 0, binding = 24, rgba32f) readonly uniform image2D caustic_receivers;
layout(std430, set = 0, binding = 25) readonly buffer CausticReceiverLamps { CausticReceivers receiver_set; };
// trace_list.comp's lists: this pass's kind's count, its pixels (x | y << 16) from list.x on.
layout(std430, set = 0, binding = 22) readonly buffer TraceCounts { uint counts[4]; };
layout(std430, set = 0, binding = 23) readonly buffer TracePixels { uint pixels[]; };

#define MRGI_UPLOAD_COLOR_ONLY
#include "common/upload_gather.glsl"
#include "common/shadowed_lamps.glsl"
#include "specular/caustic_receiver_lookup.glsl"

#include "specular/impostor_trace.glsl"

// ---- shading and back-projection --------------------------------------------------------------

// The hit's light with and without the virtual objects (eq. 3-5): lamps (shadowed when the
// technique drew maps) and the SH ambient; L_r only on real hits.
void shade_hit(Hit h, vec3 d, out vec3 l_rv, out vec3 l_r) {
  float r_p = h.real ? 1.0f : 0.0f;
  l_rv = h.albedo * ambient_irradiance(light_set.ambient_rv, h.normal) * (1.0f / MRGI_PI);
  l_r = r_p * h.albedo * ambient_irradiance(light_set.ambient_r, h.normal) * (1.0f / MRGI_PI);
  add_shadowed_lamps(h.position, h.normal, -d, h.albedo, 0.0f, 1.0f, false, r_p, specular.shadow, false, l_rv, l_r);
}

// CI(x) of eq. 8-10 where the depth validity test of Sec. 4.1.3 passes: rgb linear camera
// colour, w 1; w 0 outside the view or where the camera sees another surface there.
vec4 back_project(vec3 x) {
  vec3 c = (frame.world_to_camera * vec4(x, 1.0f)).xyz;
  if (!(c.z > 1e-3f)) return vec4(0.0f);
  vec2 ip = project_pinhole(c, frame.internal_k);
  ivec2 used = frame.internal_output_size.xy;
  if (any(lessThan(ip, vec2(0.0f))) || any(greaterThanEqual(ip, vec2(used)))) return vec4(0.0f);
  if (specular.flags.y != 0) {
    float depth = imageLoad(real_position, ivec2(ip)).w;
    if (!(depth > 0.0f) || abs(depth - c.z) > specular.params.x * c.z) return vec4(0.0f);
  }
  vec2 cp = project_pinhole(c, frame.color_k);
  ivec2 size = frame.color_depth_size.xy;
  ivec2 q = clamp(ivec2(cp), ivec2(0), size - 1);
  return vec4(srgb_decode(vec3(color_rgb8(uint(q.y * size.x + q.x))) / 255.0f), 1.0f);
}

// The internal pixel where the camera sees x itself (a real surface, or a diffuse virtual one as
// `real` says): inside the view, the G-buffer's depth there within the tolerance of x's; for a
// real x, no virtual object in front of it there (a specular one allowed when `under_specular`:
// the caustic buffer holds the surfaces under mirrors and glass, caustic_splat.frag).
// (-1, -1) where the camera does not see x.
ivec2 seen_pixel(vec3 x, bool real, bool under_specular) {
  vec3 c = (frame.world_to_camera * vec4(x, 1.0f)).xyz;
  if (!(c.z > 1e-3f)) return ivec2(-1);
  vec2 ip = project_pinhole(c, frame.internal_k);
  ivec2 used = frame.internal_output_size.xy;
  if (any(lessThan(ip, vec2(0.0f))) || any(greaterThanEqual(ip, vec2(used)))) return ivec2(-1);
  ivec2 q = ivec2(ip);
  vec4 v = imageLoad(virtual_position, q);
  if (real && v.w > 0.5f && (v.w < 1.5f || !under_specular)) return ivec2(-1);
  // A mirror or glass pixel holds no solution of its own surface (the trace writes it): another
  // specular object seen there is its base colour (shade_hit), the paper's one bounce.
  if (!real && v.w > 1.5f) return ivec2(-1);
  float depth = real ? imageLoad(real_position, q).w : (v.w > 0.5f ? (frame.world_to_camera * vec4(v.xyz, 1.0f)).z : 0.0f);
  if (!(depth > 0.0f) || abs(depth - c.z) > specular.params.x * c.z) return ivec2(-1);
  return q;
}

// The caustic irradiance on x (a real or a virtual surface) where the camera sees it, or sees it
// through a mirror or glass; a hit outside the view or hidden behind something else gets none
// (the paper's Sec. 5.2 reading of CBuf through GBuf_refl and GBuf_refr). With receiver maps
// (flags.w 2), wherever the photons landed, in view or not.
vec3 caustic_at(vec3 x, bool real) {
  // The footprint of a pixel at x's distance from the camera (a mirror's or glass's rays spread
  // more: the level is a floor on the filtering).
  if (specular.flags.w == 2) {
    vec3 to_camera = x - frame.camera_world.xyz;
    return caustic_receiver_irradiance(x, dot(to_camera, to_camera) / (frame.internal_k.x * frame.internal_k.x));
  }
  ivec2 q = seen_pixel(x, real, true);
  return q.x < 0 ? vec3(0.0f) : max(imageLoad(caustics, q).rgb, vec3(0.0f));
}

// L_env of Sec. 4.1.3: the environment's radiance along d, bilinear in the grid (the SH where
// the stage has no grid: a light estimate without an environment image).
vec3 environment_radiance(vec3 d) {
  d = normalize(d);
  int w = specular.flags.z;
  if (w > 0) return env_grid_bilinear(d, w, 0);
  SH16 y = sh_basis16(d);
  vec3 sum = vec3(0.0f);
  for (int i = 0; i < 16; ++i) sum += specular.env_sh[i].rgb * sh_get(y, i);
  return max(sum, vec3(0.0f));
}

// One path's terms of specular_compose (shared/specular_math.h), weight w, in camera units.
struct PathSum {
  vec3 rv, r, camera, env;
};
void add_path(inout PathSum sum, vec3 w, Hit h, vec3 d, float exposure) {
  if (all(lessThanEqual(w, vec3(0.0f)))) return;
  if (!h.found) {
    sum.env += w * environment_radiance(d) * exposure;
    return;
  }
  // Eq. 3-5's L'_rv and L'_r of the hit: where the camera sees the hit's surface, the
  // technique's own solution there (its lamps, shadows and indirect light: dir's VPLs with their
  // ISMs, the volumes' bounce of dlpv and dvct; and the caustics, splatted into it before this
  // pass), which is eq. 3's sum for that surface point (a virtual hit's specular lobe there is the
  // camera's view of it, not the ray's); elsewhere the lamps and the SH ambient (shade_hit: no
  // indirect light, which the technique computed only for what the camera sees) and the caustic
  // buffer where the surface is under a mirror or glass.
  vec3 l_rv, l_r;
  ivec2 seen = seen_pixel(h.position, h.real, false);
  if (seen.x >= 0) {
    l_rv = max(imageLoad(lit_rv, seen).rgb, vec3(0.0f));
    l_r = h.real ? max(imageLoad(lit_r, seen).rgb, vec3(0.0f)) : vec3(0.0f);
  } else {
    shade_hit(h, d, l_rv, l_r);
    if (specular.flags.w != 0) l_rv += h.albedo * caustic_at(h.position, h.real) * (1.0f / MRGI_PI);
  }
  vec3 tm_rv = clamp(l_rv * exposure, vec3(0.0f), vec3(1.0f));
  vec3 tm_r = clamp(l_r * exposure, vec3(0.0f), vec3(1.0f));
  sum.rv += w * tm_rv;
  sum.r += w * tm_r;
  if (h.real) {
    vec4 ci = specular.params.w > 0.5f ? back_project(h.position) : vec4(0.0f);
    sum.camera += w * (ci.w > 0.5f ? ci.rgb : tm_r);  // eq. 9: L'_r where v() fails
  }
}

int nearest_set(vec3 p) {
  int best = 0;
  float best_d = 1e30f;
  for (int i = 0; i < specular.counts.x; ++i) {
    float d = distance(p, specular.sets[i].centre.xyz) - specular.sets[i].centre.w;
    if (d < best_d) { best_d = d; best = i; }
  }
  return best;
}

layout(push_constant) uniform List { ivec4 list; };  // x this list's first entry in pixels, y its index

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  cache_caustic_receivers();
  uint at = gl_GlobalInvocationID.x;
  if (at >= counts[list.y]) return;
  uint packed = pixels[uint(list.x) + at];
  ivec2 pixel = ivec2(int(packed & 0xffffu), int(packed >> 16));
  ivec2 used = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, used))) return;
  vec4 vpos = imageLoad(virtual_position, pixel);
  if (!(vpos.w > 1.5f)) return;  // never: listed as specular
  GpuMaterial m = materials[int(vpos.w + 0.5f) - 2];
  vec3 p = vpos.xyz;
  vec3 n = normalize(imageLoad(virtual_normal, pixel).xyz);
  vec4 alb = imageLoad(virtual_albedo, pixel);
  vec3 view = normalize(p - frame.camera_world.xyz);  // camera to surface
  if (dot(n, view) > 0.0f) n = -n;
  float cos_v = max(-dot(view, n), 0.0f);
  float exposure = frame.camera.y;
  SpecularSet s = specular.sets[nearest_set(p)];
  PathSum sum;
  sum.rv = vec3(0.0f); sum.r = vec3(0.0f); sum.camera = vec3(0.0f); sum.env = vec3(0.0f);

  // GBuf_refl: the mirror direction.
  vec3 refl = mirror_direction(view, n);
  vec3 eta1;
  vec3 eta2 = vec3(0.0f);
  if (kRefractive) {
    float ior = max(m.specular.y, 1.0f);
    float f1 = fresnel_dielectric(cos_v, 1.0f / ior);
    eta1 = vec3(f1);
    // GBuf_refr: Snell at the front face, the exit in the back faces' buffer, Snell there.
    Refraction r = refract_through(p, view, n, ior, frame.world_to_clip, used, specular.back_rect);
    vec3 exit_p = r.exit_p, exit_d = r.exit_d;
    eta2 = vec3(r.transmission);
    eta2 *= transmittance_colour(alb.rgb, m.attenuation.rgb, m.specular.z, distance(p, exit_p)) *
            clamp(m.specular.w, 0.0f, 1.0f);
    Hit refr = trace_impostor(s, exit_p + exit_d * 1e-3f, exit_d);
    add_path(sum, eta2, refr, exit_d, exposure);
  } else {
    eta1 = fresnel_metal(mix(vec3(0.04f), alb.rgb, alb.a), cos_v);
  }
  // Off glass, a reflection weaker than the level's threshold is not traced (trace_list.comp
  // listed the pixel for the pass without it): it shows L_env (SpecularLevel::glass_reflection_fresnel).
  Hit h1;
  h1.found = false;
  if (kReflect) h1 = trace_impostor(s, p + refl * 1e-3f, refl);
  add_path(sum, eta1, h1, refl, exposure);

  vec3 final_linear = specular_compose(sum.rv, sum.r, sum.camera, sum.env, specular.params.y, specular.params.z);
  vec3 radiance = finite3(final_linear) / max(exposure, 1e-6f);
  imageStore(lit_rv, pixel, vec4(clamp(radiance, vec3(0.0f), vec3(60000.0f)), 1.0f));
  imageStore(lit_r, pixel, vec4(0.0f, 0.0f, 0.0f, 1.0f));
}
