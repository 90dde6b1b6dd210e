#version 460
// dvct's paper level (technique/dvct/dvct.h): every pixel shaded by cones alone, direct light
// included, as delta-voxel-cone-tracing.md Sec. 3.3 and 3.5 do it:
//   real pixel:    L_r  = Lambert x lamp x T_without + albedo / pi (E_amb_r(n) + E_without)
//                  L_rv = Lambert x lamp x T_with + albedo / pi (E_amb_rv(n) + E_with)
//   virtual pixel: L_rv = BRDF x lamp x T_with + base (1 - metallic) / pi (E_amb_rv(n) + E_with)
//                         + S_with + emission
// T: a shadow cone to each lamp (Sec. 3.5), through both visibility volumes (with) or the scene's
// alone (without), so a real surface the scene already shadows is not shadowed twice (Sec. 3.2);
// a real pixel's lamp term is the real lamps' only in L_r. E, S as dvct/indirect.comp says.
// Real pixels away from the region: the cones find nothing there but the shadow cones may cross
// it (a long shadow), so only the diffuse set is left out.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/vct_math.h"
#include "common/frame_constants.glsl"
#include "common/light_set.glsl"
#include "common/surface_shading.glsl"
#include "dvct/dvct_params.glsl"
#include "gi/vct_trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { LightSet light_set; };
AmbientIrradiance ambient_rv, ambient_r;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 5, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 8, rgba16f) readonly uniform image2D virtual_emission;
layout(set = 0, binding = 9) uniform sampler3D light_volume;
layout(set = 0, binding = 10) uniform sampler3D delta_volume;
layout(set = 0, binding = 11) uniform sampler3D scene_visibility;
layout(set = 0, binding = 12) uniform sampler3D object_visibility;
layout(set = 0, binding = 13, rgba16f) writeonly uniform image2D lit_rv;
layout(set = 0, binding = 14, rgba16f) writeonly uniform image2D lit_r;
layout(std140, set = 0, binding = 15) uniform RealMaterialUbo { DvctRealMaterials real_materials; };
layout(push_constant) uniform Params { DvctParams params_block; };
// The direct-light block's environment occlusion (shading/environment_occlusion.h), one texel
// per params.mode.z internal pixels (0: none this frame): the ambient is unshadowed here as in
// baseline, and its occlusion by the objects is the block's, not the cones'.
layout(set = 0, binding = 16, rgba16f) readonly uniform image2D env_occlusion;
layout(set = 0, binding = 17) uniform sampler3D object_light;  // the objects' ambient and emission (mode.w)
layout(std430, set = 0, binding = 18) readonly buffer EnvCells { vec4 env_cells[]; };  // params.texture.y
#include "common/env_grid.glsl"
DvctParams params;
layout(constant_id = 0) const int kDiffuseCones = 9;
layout(constant_id = 1) const bool kSpecular = true;
#include "dvct/cone_shading.glsl"
#include "shading/env_occlusion_lookup.glsl"

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  params = params_block;
  ambient_rv = light_set.ambient_rv;
  ambient_r = light_set.ambient_r;
  const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  const vec4 vpos = imageLoad(virtual_position, pixel);
  const bool is_virtual = vpos.w > 0.5f;
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
  const vec3 p = pos.xyz;
  const vec3 n = normalize(nrm.xyz);
  const vec3 view = normalize(frame.camera_world.xyz - p);
  const bool volumes = params.mode.y != 0;
  const VctVolume v = dvct_volume();
  const vec3 apex = dvct_apex(p, n);
  vec3 l_rv = vec3(0.0f), l_r = vec3(0.0f);
  const int count = min(light_set.count.x, MRGI_MAX_LIGHTS);
  for (int i = 0; i < count; ++i) {
    const ShadowLight L = light_set.lights[i];
    vec3 wi;
    const vec3 e = light_incident(L, p, wi);
    const float nl = dot(n, wi);
    if (nl <= 0.0f || all(equal(e, vec3(0.0f)))) continue;
    const vec3 lo = brdf(n, view, wi, alb.rgb, alb.a, is_virtual ? nrm.w : 1.0f, is_virtual) * e * nl;
    const bool real_lamp = L.direction_real.w > 0.5f;
    float t_with = 1.0f, t_without = 1.0f;
    if (volumes) {
      const float reach = int(L.position_type.w) == MRGI_LIGHT_DIRECTIONAL ? 1e6f : distance(L.position_type.xyz, p);
      const VctResult s = vct_trace_cone(light_volume, delta_volume, scene_visibility, object_visibility, object_light, v, apex, wi,
                                         params.cones.x, reach, 0);
      t_with = s.trans_with;
      t_without = s.trans_without;
    }
    l_rv += lo * t_with;
    if (!is_virtual && real_lamp) l_r += lo * t_without;
  }
  const float side = params.volume.w * params.trace.x;
  if (is_virtual) {
    DvctGather d;
    d.with = vec3(0.0f);
    if (volumes) d = dvct_diffuse(p, n, VCT_LIGHT);
    l_rv += alb.rgb * (1.0f - alb.a) * (1.0f / MRGI_PI) *
            (occluded_ambient(ambient_irradiance(ambient_rv, n), pixel, p, true, params.mode.z) + d.with);
    if (volumes) l_rv += dvct_specular(p, n, view, mix(vec3(0.04f), alb.rgb, alb.a), nrm.w, VCT_LIGHT).with;
    if (frame.flags.y != 0) l_rv += imageLoad(virtual_emission, pixel).rgb;
  } else {
    const vec3 amb_rv = occluded_ambient(ambient_irradiance(ambient_rv, n), pixel, p, false, params.mode.z);
    const vec3 amb_r = ambient_irradiance(ambient_r, n);
    l_r += alb.rgb * (1.0f / MRGI_PI) * amb_r;
    l_rv += alb.rgb * (1.0f / MRGI_PI) * amb_rv;
    if (volumes && dvct_near_region(p, 0.25f * side)) {
      const DvctGather d = dvct_diffuse(p, n, VCT_LIGHT | VCT_WITHOUT);
      l_rv += alb.rgb * (1.0f / MRGI_PI) * d.with;
      l_r += alb.rgb * (1.0f / MRGI_PI) * d.without;
      const vec2 rm = dvct_real_material(p);
      const DvctSpecular s = dvct_specular(p, dvct_mirror_normal(pixel, n), view, mix(vec3(0.04f), alb.rgb, rm.y), rm.x,
                                             VCT_LIGHT | VCT_WITHOUT);
      l_rv += s.with;
      l_r += s.without;
    }
  }
  // Half floats end at 65504: clamp so no Inf reaches compose.
  imageStore(lit_rv, pixel, vec4(clamp(sanitize(l_rv), vec3(0.0f), vec3(60000.0f)), 1.0f));
  imageStore(lit_r, pixel, vec4(clamp(sanitize(l_r), vec3(0.0f), vec3(60000.0f)), 1.0f));
}

