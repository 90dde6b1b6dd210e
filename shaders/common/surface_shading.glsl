// Surface shading shared by the techniques' shading passes (shading/direct_light.comp,
// dlpv/merge.comp): one copy of the BRDF and of the ambient's evaluation. Needs
// shared/mrgi_shared.h and common/light_set.glsl included first.
#ifndef MRGI_SURFACE_SHADING_GLSL
#define MRGI_SURFACE_SHADING_GLSL

// GGX (Trowbridge-Reitz) with Smith height-correlated visibility and Schlick Fresnel, the glTF
// metallic-roughness model; returns the BRDF times pi-free cosine is applied by the caller.
vec3 brdf(vec3 n, vec3 v, vec3 l, vec3 base, float metallic, float roughness, bool specular) {
  vec3 diffuse = base * (1.0f - metallic) / MRGI_PI;
  if (!specular) return base / MRGI_PI;
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  vec3 f = f0 + (1.0f - f0) * schlick_weight(dot(v, normalize(v + l)));
  return (1.0f - f) * diffuse + ggx_d_vis(n, l, v, roughness) * f;
}

// E(n) of an ambient, linear RGB, >= 0 (SH bands 0..2 can dip below 0 away from the light).
// The matrices are symmetric (light/light_stage.cpp irradiance_matrices), so n4^T M n4 is 10
// multiply-adds over the distinct products of n4, shared by the channels, instead of M n4's 16
// and a dot product per channel (every shading invocation pays this on lavapipe).
float symmetric_form(mat4 m, vec3 sq, vec3 mixed, vec3 n) {
  return m[0][0] * sq.x + m[1][1] * sq.y + m[2][2] * sq.z + m[3][3] +
         2.0f * (m[1][0] * mixed.x + m[2][0] * mixed.y + m[2][1] * mixed.z + m[3][0] * n.x + m[3][1] * n.y +
                 m[3][2] * n.z);
}
vec3 ambient_irradiance(AmbientIrradiance a, vec3 n) {
  vec3 sq = n * n, mixed = vec3(n.x * n.y, n.x * n.z, n.y * n.z);
  return max(vec3(symmetric_form(a.r, sq, mixed, n), symmetric_form(a.g, sq, mixed, n),
                  symmetric_form(a.b, sq, mixed, n)), vec3(0.0f));
}

vec3 sanitize(vec3 c) {
  return vec3(isnan(c.x) ? 0.0f : c.x, isnan(c.y) ? 0.0f : c.y, isnan(c.z) ? 0.0f : c.z);
}

// The irradiance at normal incidence a lamp gives point p (rgb; inverse square and spot cone for
// point and spot lamps) and the unit direction towards it, `wi`. No shadowing.
vec3 light_incident(ShadowLight L, vec3 p, out vec3 wi) {
  int type = int(L.position_type.w);
  if (type == MRGI_LIGHT_DIRECTIONAL) {
    wi = -L.direction_real.xyz;
    return L.intensity.rgb;
  }
  vec3 to_light = L.position_type.xyz - p;
  float d2 = max(dot(to_light, to_light), 1e-6f);
  wi = to_light * inversesqrt(d2);
  float cone = 1.0f;
  if (type == MRGI_LIGHT_SPOT) cone = spot_falloff(dot(L.direction_real.xyz, -wi), L.cone.y, L.cone.x);
  return L.intensity.rgb * cone / d2;
}

#endif  // MRGI_SURFACE_SHADING_GLSL
