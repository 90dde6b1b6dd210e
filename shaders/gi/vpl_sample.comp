#version 450
// VPLs from a reflective shadow map pair (gi/vpl.h; DIR paper Sec. 3.7): one invocation per VPL
// slot. A Halton value picks the map, the real one (R^mu: the real casters) or the virtual one
// (R^rho's virtual texels), in proportion to the texels each covers; two more Halton values
// descend that map's importance pyramid by hierarchical warping (Clarberg et al. 2005,
// mrgi_shared.h warp_step) to a texel drawn in proportion to its reflected flux's luminance. The
// VPL takes the texel's position, normal and flux, the flux divided by the probability of
// drawing it (the map's share of the slots times the texel's share of the map's luminance, times
// the slot count): the paper's intensity compensation, so the VPLs' expected sum is the maps'.
// Flags (Sec. 3.3-3.6): a VPL on a real surface of a real lamp's map is on a real path; one
// whose texel R^rho covers with a virtual surface lights real surfaces only (the paper's VPL 3:
// it cancels the real bounce the virtual object blocks).
// kGlossy (a scene with a glossy virtual material, gi/vpl.h VplSettings::glossy): a VPL on a
// virtual texel takes its material's split into a cosine emitter and a specular lobe around the
// lamp's mirror direction (shared/vpl_math.h vpl_glossy_split; the map's flux is the base colour
// times the incident flux, rsm.frag); without it, and on real texels, every VPL is diffuse.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/vpl_math.h"
#include "common/vpl.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) uniform sampler2D importance;  // the pyramid, every level (nearest)
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D rho_position;
layout(set = 0, binding = 2, rgba16f) uniform readonly image2D rho_normal;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D rho_flux;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D mu_position;
layout(set = 0, binding = 5, rgba16f) uniform readonly image2D mu_normal;
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D mu_flux;
layout(std430, set = 0, binding = 7) writeonly buffer Vpls { Vpl vpls[]; };
// The lamp's caustic photons (gi/vpl.h VplCaustics; caustic.x 0: none, never read).
#include "specular/photon.glsl"
layout(std430, set = 0, binding = 8) readonly buffer Photons { Photon photons[]; };
layout(push_constant) uniform Params {
  ivec4 slots;  // x: first slot; y: slots of this pair; z: the pyramid's top level (used side
                // 2^z); w: 1 real lamp, 0 virtual
  vec4 lamp;    // the maps' lamp (gi/rsm.h RsmView::light): xyz its position (w > 0) or the
                // direction its light travels (w < 0)
  vec4 colour;  // rgb its colour x intensity (what the maps' flux alpha is per unit of)
  mat4 caustic_view_proj;  // the photon map's view
  ivec4 caustic;           // x the photon map's side (0: no caustic VPLs)
} params;

// Caustic VPLs (caustics-DIR paper Sec. 4.2.2): a VPL on a texel of a mirror or glass object
// (its photon-map texel's point on the object is this texel's point) moves to where one of that
// texel's photons landed: the reflected or the refracted one, by a Halton value when both did
// (then with twice the flux: each is taken every second time), the only one otherwise; none: no
// VPL (its light left the scene). Its flux: the texel's incident light x the path's weight
// (Fresnel, transmittance: the photon's flux over what its texel emitted) x the albedo where it
// landed, over the probability of drawing the texel. It lights L_rv only: a virtual object is on
// its path. Returns false where the texel is not on such an object.
bool caustic_vpl(vec4 pos, vec4 flux, float weight, uint h, inout Vpl v) {
  int size = params.caustic.x;
  if (size <= 0 || !(pos.w > 1.5f)) return false;
  vec4 clip = params.caustic_view_proj * vec4(pos.xyz, 1.0f);
  if (!(clip.w > 0.0f)) return false;
  vec2 t = (clip.xy / clip.w * 0.5f + 0.5f) * float(size);
  if (any(lessThan(t, vec2(0.0f))) || any(greaterThanEqual(t, vec2(float(size))))) return false;
  ivec2 texel = ivec2(t);
  int i = texel.y * size + texel.x;
  Photon a = photons[2 * i], b = photons[2 * i + 1];
  // Reflected photons one texel in stride x stride (specular.h SpecularLevel::glass_reflection_stride):
  // the block's photon, whose flux is the block's (stride^2 texels').
  int stride = max(int(a.normal.w + 0.5f), 1);
  float a_texels = 1.0f;
  if (stride > 1) {
    ivec2 rep = texel - texel % stride;
    a = photons[2 * (rep.y * size + rep.x)];
    a_texels = float(stride * stride);
  }
  // The same surface point: within a few photon-map texels (the maps see the object from the
  // same lamp at different resolutions).
  float tolerance = 0.02f * distance(pos.xyz, params.lamp.xyz) + 0.005f;
  if (!(a.origin.w > 0.5f) || distance(a.origin.xyz, pos.xyz) > tolerance) return false;
  bool va = a.position.w > 0.5f, vb = b.position.w > 0.5f;
  v.flux = vec4(0.0f);
  v.position = vec4(0.0f);
  if (!va && !vb) return true;
  bool take_a = va && (!vb || halton(h, 7u) < 0.5f);
  Photon p = take_a ? a : b;
  float share = (va && vb) ? 2.0f : 1.0f;
  vec3 path = p.flux.rgb / max(params.colour.rgb * p.flux.w, vec3(1e-30f)) / (take_a ? a_texels : 1.0f);
  vec3 incident = max(flux.a, 0.0f) * params.colour.rgb;
  vec3 f = incident * path * p.albedo.rgb * share / weight;
  bool finite = all(lessThan(f, vec3(3.0e38f)));
  v.position = vec4(p.position.xyz, float(MRGI_VPL_VALID));
  v.normal = vec4(normalize(p.normal.xyz), 0.0f);
  v.flux = vec4(finite ? max(f, vec3(0.0f)) : vec3(0.0f), 0.0f);
  v.lobe = vec4(0.0f, 0.0f, 1.0f, -1.0f);
  v.specular = vec4(0.0f);
  return true;
}
layout(constant_id = 0) const bool kGlossy = false;

void main() {
  int j = int(gl_GlobalInvocationID.x);
  if (j >= params.slots.y) return;
  int slot = params.slots.x + j;
  Vpl v;
  v.position = vec4(0.0f);
  v.normal = vec4(0.0f, 0.0f, 1.0f, 0.0f);
  v.flux = vec4(0.0f);
  v.lobe = vec4(0.0f, 0.0f, 1.0f, -1.0f);
  v.specular = vec4(0.0f);
  int top = params.slots.z;
  vec4 total = texelFetch(importance, ivec2(0), top);
  float covered = total.z + total.w;
  uint h = uint(slot) + 1u;  // Halton index 0 is the origin in every base
  bool use_virtual = covered > 0.0f && halton(h, 2u) < total.w / covered;
  float p_map = covered > 0.0f ? (use_virtual ? total.w : total.z) / covered : 0.0f;
  float map_total = use_virtual ? total.y : total.x;
  if (p_map > 0.0f && map_total > 0.0f) {
    vec2 u = vec2(halton(h, 3u), halton(h, 5u));
    ivec2 at = ivec2(0);
    float p = 1.0f;
    for (int level = top; level > 0; --level) {
      ivec2 b = at * 2;
      vec4 c00 = texelFetch(importance, b, level - 1), c10 = texelFetch(importance, b + ivec2(1, 0), level - 1);
      vec4 c01 = texelFetch(importance, b + ivec2(0, 1), level - 1), c11 = texelFetch(importance, b + ivec2(1, 1), level - 1);
      vec4 q = use_virtual ? vec4(c00.y, c10.y, c01.y, c11.y) : vec4(c00.x, c10.x, c01.x, c11.x);
      WarpStep s = warp_step(u, q);
      at = b + s.child;
      p *= s.probability;
      u = s.u;
    }
    bool real_lamp = params.slots.w != 0;
    vec4 pos, nrm, flux;
    if (use_virtual || !real_lamp) {
      pos = imageLoad(rho_position, at);
      nrm = imageLoad(rho_normal, at);
      flux = imageLoad(rho_flux, at);
    } else {
      pos = imageLoad(mu_position, at);
      nrm = imageLoad(mu_normal, at);
      flux = imageLoad(mu_flux, at);
    }
    float weight = p * p_map * float(params.slots.y);
    if (pos.w > 0.5f && weight > 0.0f && caustic_vpl(pos, flux, weight, h, v)) {
      // moved off the mirror or glass (or dropped)
    } else if (pos.w > 0.5f && weight > 0.0f) {
      int flags = MRGI_VPL_VALID;
      if (!use_virtual && real_lamp) {
        flags |= MRGI_VPL_REAL_PATH;
        if (imageLoad(rho_position, at).w > 1.5f) flags |= MRGI_VPL_REAL_ONLY;
      }
      vec3 n = nrm.xyz;
      float len = length(n);
      v.position = vec4(pos.xyz, float(flags));
      v.normal = vec4(len > 0.0f ? n / len : vec3(0.0f, 0.0f, 1.0f), 0.0f);
      vec3 f = max(flux.rgb, vec3(0.0f)) / weight;
      vec4 specular = vec4(0.0f);
      if (kGlossy && pos.w > 1.5f && nrm.w >= 0.0f) {
        // A virtual texel of a material with a lobe: flux = base x Phi_in, flux.a = Phi_in per
        // unit of the lamp's colour.
        vec3 incident = max(flux.a, 0.0f) * params.colour.rgb;
        vec3 base = clamp(flux.rgb / max(incident, vec3(1e-30f)), vec3(0.0f), vec3(1.0f));
        VplGlossySplit s = vpl_glossy_split(incident / weight, base, clamp((pos.w - 2.0f) * 2.0f, 0.0f, 1.0f));
        f = s.diffuse_flux;
        specular = vec4(s.specular_flux, s.incident_luminance);
        vec3 towards = params.lamp.w > 0.0f ? params.lamp.xyz - pos.xyz : -params.lamp.xyz;
        float tl = length(towards);
        v.lobe = vec4(tl > 0.0f ? towards / tl : v.normal.xyz, nrm.w);
      }
      bool finite = all(lessThan(f, vec3(3.0e38f))) && all(lessThan(specular, vec4(3.0e38f)));
      v.flux = vec4(finite ? f : vec3(0.0f), 0.0f);  // no NaN or Inf VPL
      v.specular = finite ? specular : vec4(0.0f);
      if (!finite) v.lobe.w = -1.0f;
    }
  }
  vpls[slot] = v;
}
