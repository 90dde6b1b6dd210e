// The light stage's lamps with the direct-light block's real/virtual shadow-map pair (DIR eq. 1-5), one copy
// for every pass that lights points with them: shading/direct_light.comp (the camera's pixels)
// and specular/trace.comp (the points mirrors and glass show). The including shader declares,
// before including this: the LightUbo `light_set`, the compare samplers shadow_primary and
// shadow_virtual, the plain ones shadow_primary_depth and shadow_virtual_depth (read by the
// one-map ablation only); shared/mrgi_shared.h, common/light_set.glsl and
// common/surface_shading.glsl come first. `shadow_level` is the direct-light block's LevelConstants::shadow:
// x used map size / allocated size, y used size (texels), z allocated size, w PCF radius.
#ifndef MRGI_SHADOWED_LAMPS_GLSL
#define MRGI_SHADOWED_LAMPS_GLSL

const float kNormalOffsetTexels = 1.5f;  // shadow lookup moved along the normal, in texels

int cube_face(vec3 d) {
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0f ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0f ? 2 : 3;
  return d.z >= 0.0f ? 4 : 5;
}

// Where p (moved along n by kNormalOffsetTexels) falls in lamp `light`'s maps: the map
// coordinates in the used corner (xy), the depth (z) and the face (w; 0 unless a point lamp's
// cube), or w = -1 outside the frustum (lit). Once a lamp for both of its maps: they share
// the projection (the matrix is a per-pixel gather from the uniform buffer on lavapipe).
vec4 shadow_coord(int light, ShadowLight L, vec3 p, vec3 n, vec4 shadow_level) {
  int type = int(L.position_type.w);
  int face = 0;
  float texel_world;
  if (type == MRGI_LIGHT_DIRECTIONAL) {
    texel_world = L.cone.w / shadow_level.y;
  } else {
    vec3 d = p - L.position_type.xyz;
    if (L.layers.z == 6) face = cube_face(d);
    texel_world = L.cone.z * length(d) / shadow_level.y;
  }
  vec3 q = p + n * (kNormalOffsetTexels * texel_world);
  vec4 clip = light_set.face_view_proj[light * 6 + face] * vec4(q, 1.0f);
  if (!(clip.w > 0.0f)) return vec4(0.0f, 0.0f, 0.0f, -1.0f);
  vec3 ndc = clip.xyz / clip.w;
  if (any(greaterThan(abs(ndc.xy), vec2(1.0f))) || ndc.z > 1.0f || ndc.z < 0.0f) return vec4(0.0f, 0.0f, 0.0f, -1.0f);
  return vec4((ndc.xy * 0.5f + 0.5f) * shadow_level.x, ndc.z, float(face));
}

// Fraction of the lamp seen through one map at c (shadow_coord; 1 lit, 0 shadowed), PCF over
// (2r+1)^2 bilinear compare taps. A lamp without maps (first_layer < 0) is unshadowed.
float shadow_test(sampler2DArrayShadow map, int first_layer, vec4 c, vec4 shadow_level) {
  if (c.w < 0.0f || first_layer < 0) return 1.0f;
  float texel = 1.0f / shadow_level.z;
  vec2 lo = vec2(0.5f * texel), hi = vec2(shadow_level.x - 0.5f * texel);
  int r = int(shadow_level.w);
  float sum = 0.0f;
  for (int j = -r; j <= r; ++j) {
    for (int i = -r; i <= r; ++i) {
      vec2 t = clamp(c.xy + vec2(i, j) * texel, lo, hi);
      sum += texture(map, vec4(t, float(first_layer) + c.w, c.z));
    }
  }
  return sum / float((2 * r + 1) * (2 * r + 1));
}

// Adds every lamp's direct light at p (normal n, towards the viewer v) to both solutions:
//   L_rv += L_o * min(st_r, st_v)          (every lamp, every surface; eq. 1, 3)
//   L_r  += L_o * r(lamp) * r_p * st_r     (real lamps on real points, real casters; eq. 2)
// is_virtual selects the BRDF (glTF metallic-roughness; real surfaces are Lambertian).
// one_map: DirAblation::one_shadow_map (shading/direct_light.comp's kOneShadowMap says more).
void add_shadowed_lamps(vec3 p, vec3 n, vec3 v, vec3 albedo, float metallic, float roughness, bool is_virtual,
                        float r_p, vec4 shadow_level, bool one_map, inout vec3 l_rv, inout vec3 l_r) {
  int count = min(light_set.count.x, MRGI_MAX_LIGHTS);
  for (int i = 0; i < count; ++i) {
    ShadowLight L = light_set.lights[i];
    vec3 wi;
    vec3 irradiance_rgb = light_incident(L, p, wi);
    float nl = dot(n, wi);
    if (nl <= 0.0f || all(equal(irradiance_rgb, vec3(0.0f)))) continue;
    vec3 lo = brdf(n, v, wi, albedo, metallic, roughness, is_virtual) * irradiance_rgb * nl;
    vec4 at = shadow_coord(i, L, p, n, shadow_level);
    float st_primary = shadow_test(shadow_primary, L.layers.x, at, shadow_level);
    bool real_lamp = L.direction_real.w > 0.5f;
    if (real_lamp) {
      float st_v = L.layers.y >= 0 ? shadow_test(shadow_virtual, L.layers.y, at, shadow_level) : 1.0f;
      if (one_map && L.layers.x >= 0 && L.layers.y >= 0 && at.w >= 0.0f) {
        bool real_nearer = textureLod(shadow_primary_depth, vec3(at.xy, float(L.layers.x) + at.w), 0.0f).r <=
                           textureLod(shadow_virtual_depth, vec3(at.xy, float(L.layers.y) + at.w), 0.0f).r;
        st_primary = real_nearer ? st_primary : 1.0f;  // the real caster behind is lost
        st_v = real_nearer ? 1.0f : st_v;
      }
      l_rv += lo * min(st_primary, st_v);
      l_r += lo * r_p * st_primary;
    } else {
      l_rv += lo * st_primary;  // the virtual lamp's map holds every caster
    }
  }
}

#endif  // MRGI_SHADOWED_LAMPS_GLSL
