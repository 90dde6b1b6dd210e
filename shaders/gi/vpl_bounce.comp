#version 450
// The bounce light source (gi/vpl_bounce.h; DIR paper Sec. 3.7, "a special primary light source
// that performs one light bounce", and the path flags of eq. 9-10): new VPLs on the scene's
// surfaces lit by the previous frame's VPLs, seen through the previous frame's ISMs. One
// workgroup per bounce slot, one invocation per candidate point:
//   1. the candidate is a point of the scene's point clouds (as the ISMs use them): even
//      invocations the real G-buffer at a Halton position (inside the influence sphere),
//      odd ones the virtual meshes (gi/virtual_points.glsl);
//   2. a source VPL of the previous frame is drawn by a Halton value in proportion to its flux's
//      luminance (the paper's importance sampling of the source);
//   3. the source's light reaching the point (gi/vpl_light.glsl: a point VPL's or an environment
//      region's, over the draw's probability) times the point's diffuse albedo and the area it
//      stands for is the candidate's reflected flux; its visibility is the source's real and
//      virtual ISMs.
// The paper keeps the strongest candidate of a slot (reversed depth test) and does not say how
// its intensity is compensated; keeping the maximum biases the sum. mrgi keeps one candidate
// drawn in proportion to the luminance of its flux and divides its flux by that probability
// (resampled importance sampling): the slot's expected flux is its candidates' sum, and strong
// candidates still win most of the time.
// Flags (eq. 9, ir copied): a point on a virtual surface ends a real path; a real point the
// source reaches in L_r but a virtual object hides from it in L_rv carries ir = 1 (lights real
// surfaces only, in L_r: it cancels the bounce the object blocks); an ir source spawns only real
// points and ignores the virtual casters (Sec. 3.6).
// kGlossy (gi/vpl_bounce.h VplBounceSettings::glossy): the sources' specular lobes light the
// candidates (the paper's "glossy light bounce"), and a candidate on a virtual surface whose
// material has a lobe becomes a glossy VPL lit from its source's direction (vpl_math.h
// vpl_glossy_split); the draws weigh the lobe's flux with the cosine emitter's.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/vpl_math.h"
#include "common/vpl.glsl"
#include "common/scene_materials.glsl"

#define MRGI_BOUNCE_CANDIDATES 64
#define MRGI_BOUNCE_MAX_SOURCES 256
layout(local_size_x = MRGI_BOUNCE_CANDIDATES) in;
layout(std430, set = 0, binding = 0) readonly buffer Vpls { Vpl vpls[]; };  // the previous frame's
layout(set = 0, binding = 1, rg32f) readonly uniform image2D ism_distances;  // the previous frame's
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_albedo;
layout(std430, set = 0, binding = 5) readonly buffer Vertices { float vertex_words[]; };
layout(std430, set = 0, binding = 6) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = 7) readonly buffer Ranges { ivec4 ranges[]; };
layout(std430, set = 0, binding = 8) readonly buffer RangeMaterials { int range_material[]; };
layout(std430, set = 0, binding = 9) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 10) uniform sampler2DArray base_color_maps;
layout(std430, set = 0, binding = 11) writeonly buffer Bounce { Vpl bounce[]; };
layout(push_constant) uniform Params {
  ivec4 source;  // x: the previous frame's VPL slots; y: its ISM side; z: its tiles per row; w: bounce slots
  ivec4 points;  // x, y: the G-buffer's used size; z: virtual triangles; w: virtual ranges
  vec4 sphere;   // xyz: centre of the influence sphere (m); w: its radius
  vec4 test;     // x: the VPLs' 1/d^2 clamp distance (m); y, z: ISM bias relative and metres
  vec4 camera;   // x, y: the G-buffer's focal lengths in its pixels
} params;
layout(constant_id = 0) const bool kGlossy = false;
const bool kGlossyLobes = kGlossy;  // gi/vpl_light.glsl
#include "gi/virtual_points.glsl"
#include "gi/vpl_light.glsl"

shared float cdf[MRGI_BOUNCE_MAX_SOURCES];
shared float weight[MRGI_BOUNCE_CANDIDATES];
shared int chosen;

void main() {
  int slot = int(gl_WorkGroupID.x);
  int k = int(gl_LocalInvocationID.x);
  int sources = min(params.source.x, MRGI_BOUNCE_MAX_SOURCES);
  for (int j = k; j < sources; j += MRGI_BOUNCE_CANDIDATES) {
    Vpl v = vpls[j];
    // The source's power: a point VPL's flux; a directional one's irradiance over its map's
    // cross-section (the disk of its half side), so both kinds are drawn by what they bring.
    float power = vpl_directional(v) ? MRGI_PI * v.normal.w * v.normal.w : 1.0f;
    vec3 reflected = max(v.flux.rgb, vec3(0.0f)) + (kGlossy && v.lobe.w >= 0.0f ? max(v.specular.rgb, vec3(0.0f)) : vec3(0.0f));
    float l = (int(v.position.w) & MRGI_VPL_VALID) != 0 ? luminance(reflected) * power : 0.0f;
    cdf[j] = l > 0.0f && l < 3.0e38f ? l : 0.0f;
  }
  barrier();
  if (k == 0) {
    float sum = 0.0f;
    for (int j = 0; j < sources; ++j) {
      sum += cdf[j];
      cdf[j] = sum;
    }
  }
  barrier();
  float total = sources > 0 ? cdf[sources - 1] : 0.0f;

  // 1. The candidate point.
  bool has_virtual = params.points.z > 0;
  bool want_virtual = has_virtual && (k & 1) == 1;
  int per_kind = has_virtual ? MRGI_BOUNCE_CANDIDATES / 2 : MRGI_BOUNCE_CANDIDATES;
  int slots = params.source.w;
  uint index = uint(slot * per_kind + (has_virtual ? k / 2 : k)) + 1u;  // Halton index 0 is the origin
  bool ok = total > 0.0f;
  vec3 x = vec3(0.0f), n = vec3(0.0f, 0.0f, 1.0f), albedo = vec3(0.0f);
  vec3 base = vec3(0.0f);
  float metallic = 0.0f, roughness = -1.0f;  // the candidate's lobe (kGlossy, virtual; < 0 none)
  float area = 0.0f;
  if (want_virtual) {
    VirtualPoint p = virtual_point(vec3(halton(index, 2u), halton(index, 3u), halton(index, 5u)), params.points.z,
                                   params.points.w);
    x = p.position;
    n = p.normal;
    GpuMaterial m = materials[range_material[p.range]];
    base = m.base_color_factor.rgb;
    if (m.params.z >= 0.0f) base *= textureLod(base_color_maps, vec3(p.uv, m.params.z), 0.0f).rgb;
    albedo = base * (1.0f - m.params.x);  // diffuse: base colour x (1 - metallic)
    if (kGlossy) {
      metallic = m.params.x;
      roughness = m.params.y;
    }
    area = p.area / float(slots * per_kind);
  } else {
    ivec2 size = params.points.xy;
    ivec2 pixel = min(ivec2(vec2(halton(index, 2u), halton(index, 3u)) * vec2(size)), size - 1);
    vec4 pos = imageLoad(real_position, pixel);
    vec3 nrm = imageLoad(real_normal, pixel).xyz;
    float len = length(nrm);
    ok = ok && pos.w > 0.0f && len > 0.0f && distance(pos.xyz, params.sphere.xyz) <= params.sphere.w;
    x = pos.xyz;
    n = len > 0.0f ? nrm / len : n;
    albedo = imageLoad(real_albedo, pixel).rgb;
    // The pixel's footprint at its depth times the pixels a candidate stands for.
    area = pos.w * pos.w / (params.camera.x * params.camera.y) * float(size.x * size.y) / float(slots * per_kind);
  }

  // 2. The source VPL, drawn in proportion to its flux's luminance.
  float flux_weight = 0.0f;
  vec3 flux = vec3(0.0f);
  vec4 lobe = vec4(0.0f, 0.0f, 1.0f, -1.0f), specular = vec4(0.0f);
  int flags = 0;
  int j = 0;
  if (ok) {
    float target = halton(index, want_virtual ? 13u : 7u) * total;  // bases apart from the point's
    int lo = 0, hi = sources - 1;
    while (lo < hi) {
      int mid = (lo + hi) / 2;
      if (cdf[mid] > target) hi = mid; else lo = mid + 1;
    }
    j = lo;
    Vpl v = vpls[j];
    float p_source = (cdf[j] - (j > 0 ? cdf[j - 1] : 0.0f)) / total;
    int source_flags = int(v.position.w);
    bool source_ir = (source_flags & MRGI_VPL_REAL_ONLY) != 0;
    bool source_real = (source_flags & MRGI_VPL_REAL_PATH) != 0;
    vec3 e = vpl_incident(v, x, n, params.test.x);
    // 3. Visibility: the source's ISMs of the previous frame.
    if (p_source > 0.0f && any(greaterThan(e, vec3(0.0f))) && !(want_virtual && source_ir)) {
      vec2 stored;
      vec2 st = vpl_visibility(v, j, x, n, params.source.y, params.source.z, params.test.y, params.test.z, stored);
      bool st_r = st.x > 0.5f, st_v = st.y > 0.5f;
      if (want_virtual) {
        flags = st_r && st_v ? MRGI_VPL_VALID : 0;                  // a virtual surface: L_rv only
      } else if (source_ir) {
        flags = st_r ? MRGI_VPL_VALID | MRGI_VPL_REAL_PATH | MRGI_VPL_REAL_ONLY : 0;  // ir copied
      } else if (source_real) {
        flags = st_r ? MRGI_VPL_VALID | MRGI_VPL_REAL_PATH | (st_v ? 0 : MRGI_VPL_REAL_ONLY) : 0;
      } else {
        flags = st_r && st_v ? MRGI_VPL_VALID : 0;                  // the path met a virtual object
      }
      vec3 incident = max(e, vec3(0.0f)) * (area / p_source);  // Phi_in of the candidate's area
      flux = albedo * incident;
      if (kGlossy && want_virtual && roughness >= 0.0f) {
        VplGlossySplit s = vpl_glossy_split(incident, base, metallic);
        flux = s.diffuse_flux;
        specular = vec4(s.specular_flux, s.incident_luminance);
        lobe = vec4(vpl_direction(v, x), roughness);
      }
      float w = luminance(flux + specular.rgb);
      flux_weight = flags != 0 && w > 0.0f && w < 3.0e38f ? w : 0.0f;
    }
  }
  weight[k] = flux_weight;
  barrier();
  if (k == 0) {
    float sum = 0.0f;
    for (int c = 0; c < MRGI_BOUNCE_CANDIDATES; ++c) sum += weight[c];
    int pick = -1;
    if (sum > 0.0f) {
      float target = halton(uint(slot) + 1u, 11u) * sum, run = 0.0f;
      for (int c = 0; c < MRGI_BOUNCE_CANDIDATES && pick < 0; ++c) {
        run += weight[c];
        if (run > target && weight[c] > 0.0f) pick = c;
      }
      if (pick < 0)  // rounding: the last candidate with weight
        for (int c = MRGI_BOUNCE_CANDIDATES - 1; c >= 0 && pick < 0; --c)
          if (weight[c] > 0.0f) pick = c;
    }
    chosen = pick;
    weight[0] = sum;  // read after the barrier below by the chosen invocation
    if (pick < 0) {
      Vpl empty;
      empty.position = vec4(0.0f);
      empty.normal = vec4(0.0f, 0.0f, 1.0f, 0.0f);
      empty.flux = vec4(0.0f);
      empty.lobe = vec4(0.0f, 0.0f, 1.0f, -1.0f);
      empty.specular = vec4(0.0f);
      bounce[slot] = empty;
    }
  }
  float mine = flux_weight;
  barrier();
  if (chosen == k) {
    Vpl b;
    b.position = vec4(x, float(flags));
    b.normal = vec4(n, 0.0f);
    float scale = weight[0] / mine;  // over the probability mine / sum of the draw
    vec3 f = flux * scale;
    vec4 sp = specular * scale;
    bool finite = all(lessThan(f, vec3(3.0e38f))) && all(lessThan(sp, vec4(3.0e38f)));
    b.flux = vec4(finite ? f : vec3(0.0f), 0.0f);
    b.lobe = finite ? lobe : vec4(0.0f, 0.0f, 1.0f, -1.0f);
    b.specular = finite ? sp : vec4(0.0f);
    bounce[slot] = b;
  }
}
