#version 460
// Caustic photons of one spot lamp (caustics-DIR paper Sec. 4.2 and 5.2, after Wyman and Davis
// 2006): every texel of the lamp's photon G-buffer that sees a reflective or refractive object
// sends a photon along the reflected ray and, through glass, one along the twice refracted ray
// (the camera's searches: specular/impostor_trace.glsl), to where it meets the impostors.
// Intensity by the texel's share of the lamp (Shah et al. 2007 count the texels; each texel here
// is one photon): I(w) x spot cone x the texel's solid angle x Fresnel (x T_c through glass).
// Photon 2 i is texel i's reflected one, 2 i + 1 its refracted one; position w 0 where none.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/scene_materials.glsl"
#include "specular/photon.glsl"
#include "specular/specular_params.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform SpecularUbo { SpecularConstants specular; };
layout(std430, set = 0, binding = 1) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D photon_position;  // front faces
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D photon_normal;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D back_position;    // back faces
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D back_normal;
layout(set = 0, binding = 6, rgba32f) readonly uniform image2D impostor_position;
layout(set = 0, binding = 7, rgba8_snorm) readonly uniform image2D impostor_normal;
layout(set = 0, binding = 8, rgba8) readonly uniform image2D impostor_albedo;
layout(std430, set = 0, binding = 9) writeonly buffer Photons { Photon photons[]; };
// The photons that landed somewhere, listed for the splat's indirect draw (a point each;
// vertex_count reset to 0 before this pass).
layout(std430, set = 0, binding = 10) writeonly buffer PhotonList { uint photon_list[]; };
layout(std430, set = 0, binding = 11) buffer PhotonDraw {
  uint vertex_count, instance_count, first_vertex, first_instance;
} photon_draw;
layout(push_constant) uniform Lamp {
  mat4 view_proj;  // the photon G-buffer's view (Vulkan clip)
  vec4 position;   // xyz lamp position; w map size (texels)
  vec4 intensity;  // rgb W/sr; w 2 tan(half field of view) (the texel's angular size x size)
  vec4 axis;       // xyz spot direction; w cos(inner)
  vec4 cone;       // x cos(outer); yzw the map's view axis
};

#include "specular/impostor_trace.glsl"

int nearest_set(vec3 p) {
  int best = 0;
  float best_d = 1e30f;
  for (int i = 0; i < specular.counts.x; ++i) {
    float d = distance(p, specular.sets[i].centre.xyz) - specular.sets[i].centre.w;
    if (d < best_d) { best_d = d; best = i; }
  }
  return best;
}

// origin: the texel's point on the object (w 1), or w 0 where the texel sees none;
// emitted: the lamp's light the texel stands for, per unit of its colour; stride: texels per side
// between photons of its kind.
void store(uint i, Hit h, vec3 flux, vec4 origin, float emitted, int stride) {
  bool ok = h.found && any(greaterThan(flux, vec3(0.0f)));
  photons[i].position = vec4(h.position, ok ? (h.real ? 1.0f : 2.0f) : 0.0f);
  photons[i].flux = vec4(ok ? flux : vec3(0.0f), emitted);
  photons[i].normal = vec4(ok ? h.normal : vec3(0.0f, 1.0f, 0.0f), float(stride));
  photons[i].albedo = vec4(ok ? h.albedo : vec3(0.0f), 0.0f);
  photons[i].origin = origin;
  if (ok) photon_list[atomicAdd(photon_draw.vertex_count, 1u)] = i;
}

void main() {
  int size = int(position.w);
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel == ivec2(0)) photon_draw.instance_count = 1u;
  if (any(greaterThanEqual(texel, ivec2(size)))) return;
  uint index = uint(texel.y * size + texel.x);
  Hit none;
  none.found = false;
  vec4 pos = imageLoad(photon_position, texel);
  if (!(pos.w > 1.5f)) {
    store(2u * index, none, vec3(0.0f), vec4(0.0f), 0.0f, 1);
    store(2u * index + 1u, none, vec3(0.0f), vec4(0.0f), 0.0f, 1);
    return;
  }
  GpuMaterial m = materials[int(pos.w + 0.5f) - 2];
  vec3 p = pos.xyz;
  vec3 n = normalize(imageLoad(photon_normal, texel).xyz);
  vec3 d = normalize(p - position.xyz);
  if (dot(n, d) > 0.0f) n = -n;
  // The texel's solid angle: (2 tan(half) / size)^2 cos^3 of its angle from the map's axis.
  float c_axis = max(dot(d, cone.yzw), 1e-3f);
  float texel_angle = intensity.w / float(size);
  float emitted = spot_falloff(dot(d, axis.xyz), cone.x, axis.w) * texel_angle * texel_angle * c_axis * c_axis * c_axis;
  vec3 flux = intensity.rgb * emitted;
  vec4 origin = vec4(p, 1.0f);
  float cos_i = max(-dot(d, n), 0.0f);
  SpecularSet s = specular.sets[nearest_set(p)];
  int kind = int(m.specular.x + 0.5f);
  vec3 refl = mirror_direction(d, n);
  vec3 eta1;
  if (kind == SPECULAR_REFRACTIVE) {
    float ior = max(m.specular.y, 1.0f);
    eta1 = vec3(fresnel_dielectric(cos_i, 1.0f / ior));
    Refraction r = refract_through(p, d, n, ior, view_proj, ivec2(size), ivec4(0, 0, size, size));
    // The base colour is m's factor: the photon map holds no texture coordinates.
    vec3 t = r.transmission * transmittance_colour(m.base_color_factor.rgb, m.attenuation.rgb, m.specular.z,
                                                   distance(p, r.exit_p)) * clamp(m.specular.w, 0.0f, 1.0f);
    store(2u * index + 1u, trace_impostor(s, r.exit_p + r.exit_d * 1e-3f, r.exit_d), flux * t, origin, emitted, 1);
  } else {
    eta1 = fresnel_metal(mix(vec3(0.04f), m.base_color_factor.rgb, m.params.x), cos_i);
    store(2u * index + 1u, none, vec3(0.0f), origin, emitted, 1);
  }
  // Off glass, one texel's reflected photon per stride x stride block, with the block's flux
  // (SpecularLevel::glass_reflection_stride; the other texels' reflected photons are none, their
  // stride says where the block's is: gi/vpl_sample.comp's caustic VPLs take it from there).
  int stride = kind == SPECULAR_REFRACTIVE ? max(int(specular.level.x + 0.5f), 1) : 1;
  if (stride > 1 && any(notEqual(texel % stride, ivec2(0)))) {
    store(2u * index, none, vec3(0.0f), origin, emitted, stride);
  } else {
    store(2u * index, trace_impostor(s, p + refl * 1e-3f, refl), flux * eta1 * float(stride * stride), origin, emitted, stride);
  }
}
