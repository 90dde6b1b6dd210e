// dvct's per-pixel cone sets (delta-voxel-cone-tracing.md Sec. 3.1, 3.3), shared by indirect.comp
// (the levels that light directly with the direct-light block's shadow maps) and shade.comp (the paper's
// level, shadow cones too). Needs, declared before it: shared/mrgi_shared.h, shared/vct_math.h,
// gi/vct_trace.glsl, common/light_set.glsl, common/surface_shading.glsl, the samplers
// light_volume, delta_volume, scene_visibility, object_visibility, object_light (the objects'
// ambient and emission, read by the specular cone alone), `DvctParams params`,
// common/env_grid.glsl (its env_cells buffer),
// `DvctRealMaterials real_materials`,
// `AmbientIrradiance ambient_rv`, and the specialisation constants kDiffuseCones (cones in the
// diffuse set, 0 none) and kSpecular (the specular cone compiled in).
#ifndef MRGI_DVCT_CONE_SHADING_GLSL
#define MRGI_DVCT_CONE_SHADING_GLSL

VctVolume dvct_volume() {
  VctVolume v;
  v.origin = params.volume.xyz;
  v.voxel_size = params.volume.w;
  v.cells = params.trace.x;
  v.texture_cells = params.texture.x;
  v.max_lod = params.trace.y;
  v.occlusion_floor = params.trace.z;
  v.step_scale = params.trace.w;
  return v;
}

// Whether p is within `margin` metres of the region (the volumes' cube).
bool dvct_near_region(vec3 p, float margin) {
  vec3 lo = params.volume.xyz - vec3(margin), hi = params.volume.xyz + vec3(params.volume.w * params.trace.x + margin);
  return all(greaterThanEqual(p, lo)) && all(lessThanEqual(p, hi));
}

// A real surface's (roughness, metallic) at p: the first real material region holding it, else a
// rough dielectric (Lambert), what every real pixel is without hints.
vec2 dvct_real_material(vec3 p) {
  const int n = min(real_materials.count.x, DVCT_MAX_REAL_MATERIALS);
  for (int i = 0; i < n; ++i) {
    const vec4 lo = real_materials.min_roughness[i], hi = real_materials.max_metallic[i];
    if (all(greaterThanEqual(p, lo.xyz)) && all(lessThanEqual(p, hi.xyz))) return vec2(lo.w, hi.w);
  }
  return vec2(1.0f, 0.0f);
}

// A cone's apex: one voxel off the surface along its normal, so the surface's own voxel does not
// occlude the cones leaving it (vct_trace_cone's first sample is a voxel further).
vec3 dvct_apex(vec3 p, vec3 n) { return p + n * params.volume.w; }

// The cosine-weighted sums of the diffuse cone set around n: irradiance with and without the
// objects (rgb). The ambient (the light stage's SH) is not shaded by the cones: technique/dvct/dvct.h
// says what that was measured to cost.
struct DvctGather {
  vec3 with, without;
};

DvctGather dvct_diffuse(vec3 p, vec3 n, int flags) {
  DvctGather g;
  g.with = vec3(0.0f);
  g.without = vec3(0.0f);
  const VctVolume v = dvct_volume();
  const vec3 t = abs(n.z) < 0.999f ? normalize(cross(vec3(0.0f, 0.0f, 1.0f), n)) : vec3(1.0f, 0.0f, 0.0f);
  const vec3 b = cross(n, t);
  const vec3 apex = dvct_apex(p, n);
  for (int i = 0; i < kDiffuseCones; ++i) {
    const VctCone c = vct_diffuse_cone(i, kDiffuseCones);
    const vec3 dir = normalize(t * c.dir.x + b * c.dir.y + n * c.dir.z);
    const VctResult r = vct_trace_cone(light_volume, delta_volume, scene_visibility, object_visibility, object_light, v, apex, dir,
                                       c.aperture, params.cones.z, flags);
    g.with += c.weight * r.light_with;
    g.without += c.weight * r.light_without;
  }
  return g;
}

// A real glossy pixel's normal for its mirror direction: the mean of the G-buffer's normals at
// `pixel` and 2 pixels away on each side that face within 25 degrees of its own. The depth
// camera's noise tilts single normals by a few degrees, which a near-mirror cone turns into
// speckle in the objects' reflection (glossy_floor_white_sphere). Needs `real_normal` and `frame`.
vec3 dvct_mirror_normal(ivec2 pixel, vec3 n) {
  const ivec2 last = frame.internal_output_size.xy - 1;
  vec3 sum = n;
  for (int k = 0; k < 4; ++k) {
    const ivec2 o = k < 2 ? ivec2(k == 0 ? -2 : 2, 0) : ivec2(0, k == 2 ? -2 : 2);
    const vec3 m = imageLoad(real_normal, clamp(pixel + o, ivec2(0), last)).xyz;
    const float len = length(m);
    if (len > 0.0f && dot(m, n) > 0.9f * len) sum += m / len;
  }
  return normalize(sum);
}

// The specular cone around v's mirror direction: reflected radiance with and without the objects
// (the cone's light plus the ambient's radiance where the cone leaves the region open, both
// times the lobe's directional albedo vct_specular_weight).
struct DvctSpecular {
  vec3 with, without;
};

DvctSpecular dvct_specular(vec3 p, vec3 n, vec3 view, vec3 f0, float roughness, int flags) {
  DvctSpecular s;
  s.with = vec3(0.0f);
  s.without = vec3(0.0f);
  const float nv = dot(n, view);
  if (!kSpecular || roughness >= params.cones.w || nv <= 0.0f) return s;
  const vec3 refl = reflect(-view, n);
  const float aperture = vct_specular_aperture(roughness, params.cones.y);
  // A glancing mirror direction runs along the surface it leaves, inside that surface's own voxels
  // (trilinear reads spread it over a voxel either side): the cone starts where its axis is two
  // voxels above the surface (at most 8 voxels along it), so a glossy table at the camera's
  // glancing angle is not occluded by itself before the reflected object.
  const float lift = 2.0f / max(dot(refl, n), 0.25f) - 1.0f;
  const VctResult r = vct_trace_cone(light_volume, delta_volume, scene_visibility, object_visibility, object_light, dvct_volume(),
                                     dvct_apex(p, n) + refl * (lift * params.volume.w),
                                     refl, aperture, params.cones.z,
                                     params.mode.w != 0 ? flags | VCT_OBJECT_LIGHT : flags);
  // The environment seen along the mirror direction: the environment grid's mean radiance over
  // the cone (common/env_grid.glsl). Not the ambient's irradiance over pi (the cosine-weighted
  // mean over the hemisphere around it), which it falls back to without an environment image: a
  // glancing reflection on a floor looks at the horizon, and that mean takes in the bright sky
  // above it, which an object in the reflection was then measured to hide (a glossy floor under
  // a room's light: the reflection darkened where the truth brightens).
  const vec3 env = params.texture.y > 0.5f
                       ? env_grid_cone(refl, 0.5f * aperture, int(params.texture.y), int(params.texture.z))
                       : ambient_irradiance(ambient_rv, refl) * (1.0f / MRGI_PI);
  const vec3 w = vct_specular_weight(f0, roughness, nv);
  s.with = w * (r.light_with + env * r.trans_with);
  s.without = w * (r.light_without + env * r.trans_without);
  return s;
}

#endif  // MRGI_DVCT_CONE_SHADING_GLSL
