// Surface shading shared by the techniques' shading passes (baseline/shade_direct.comp,
// dlpv/merge.comp): one copy of the BRDF and of the ambient's evaluation. Needs
// shared/mrgi_shared.h and common/light_set.glsl included first.
#ifndef MRGI_SURFACE_SHADING_GLSL
#define MRGI_SURFACE_SHADING_GLSL

// GGX (Trowbridge-Reitz) with Smith height-correlated visibility and Schlick Fresnel, the glTF
// metallic-roughness model; returns the BRDF times pi-free cosine is applied by the caller.
vec3 brdf(vec3 n, vec3 v, vec3 l, vec3 base, float metallic, float roughness, bool specular) {
  vec3 diffuse = base * (1.0f - metallic) / MRGI_PI;
  if (!specular) return base / MRGI_PI;
  vec3 h = normalize(v + l);
  float nl = max(dot(n, l), 0.0f), nv = max(dot(n, v), 1e-4f), nh = max(dot(n, h), 0.0f);
  float a = roughness * roughness, a2 = a * a;
  float d = a2 / (MRGI_PI * pow(nh * nh * (a2 - 1.0f) + 1.0f, 2.0f));
  float vis = 0.5f / max(nl * sqrt(nv * nv * (1.0f - a2) + a2) + nv * sqrt(nl * nl * (1.0f - a2) + a2), 1e-6f);
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  vec3 f = f0 + (1.0f - f0) * pow(1.0f - max(dot(v, h), 0.0f), 5.0f);
  return (1.0f - f) * diffuse + d * vis * f;
}

// E(n) of an ambient, linear RGB, >= 0 (SH bands 0..2 can dip below 0 away from the light).
vec3 ambient_irradiance(AmbientIrradiance a, vec3 n) {
  vec4 n4 = vec4(n, 1.0f);
  return max(vec3(dot(n4, a.r * n4), dot(n4, a.g * n4), dot(n4, a.b * n4)), vec3(0.0f));
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
