#version 460
// dvct (technique/dvct/dvct.h) at the levels that light directly with the direct-light block's shadow maps:
// the cone-traced light at one G-buffer pixel in `mode.x` x `mode.x` (the block's first, as
// dir's VPL shading picks it), packed as dir's indirect (gi/indirect_pack.glsl), which
// the direct-light block's shading pass up-samples by surface and adds to both solutions
// (shading/direct_light.comp, its screen input). What it adds on top of the direct-light block's direct light and ambient:
//   real pixel near the region:
//     L_rv += albedo / pi E_with    + S_with
//     L_r  += albedo / pi E_without + S_without
//   virtual pixel:
//     L_rv += base (1 - metallic) / pi E_with + S_with
//   (E: the diffuse cones' irradiance, with the objects from the light volume through both
//   visibility volumes, without them from light - delta through the scene's; S: the specular
//   cone, real surfaces with a glossy hint only; the direct-light block adds the ambient unshadowed).
// Real pixels farther than a quarter of the region's side from it keep both solutions as
// the direct-light block makes them: the paper's region is where the objects' influence is (Sec. 3.4).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/vct_math.h"
#include "common/frame_constants.glsl"
#include "common/light_set.glsl"
#include "common/surface_shading.glsl"
#include "gi/indirect_pack.glsl"
#include "dvct/dvct_params.glsl"
#include "gi/vct_trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { LightSet light_set; };
AmbientIrradiance ambient_rv;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 5, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 8) uniform sampler3D light_volume;
layout(set = 0, binding = 9) uniform sampler3D delta_volume;
layout(set = 0, binding = 10) uniform sampler3D scene_visibility;
layout(set = 0, binding = 11) uniform sampler3D object_visibility;
layout(set = 0, binding = 12, rgba32ui) writeonly uniform uimage2D indirect;
layout(std140, set = 0, binding = 13) uniform RealMaterialUbo { DvctRealMaterials real_materials; };
layout(set = 0, binding = 14) uniform sampler3D object_light;  // the objects' ambient and emission (mode.w)
layout(std430, set = 0, binding = 15) readonly buffer EnvCells { vec4 env_cells[]; };  // params.texture.y
#include "common/env_grid.glsl"
layout(push_constant) uniform Params { DvctParams params_block; };
DvctParams params;
layout(constant_id = 0) const int kDiffuseCones = 9;
layout(constant_id = 1) const bool kSpecular = true;
#include "dvct/cone_shading.glsl"

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  params = params_block;
  ambient_rv = light_set.ambient_rv;
  const int step = max(params.mode.x, 1);
  const ivec2 low = (frame.internal_output_size.xy + step - 1) / step;
  const ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, low))) return;
  const ivec2 pixel = min(texel * step, frame.internal_output_size.xy - 1);
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
    if (!(pos.w > 0.0f)) {
      imageStore(indirect, texel, uvec4(0u));  // no surface: a key that matches nothing
      return;
    }
  }
  const vec3 p = pos.xyz;
  const vec3 n = normalize(nrm.xyz);
  const vec3 view = normalize(frame.camera_world.xyz - p);
  vec3 rv = vec3(0.0f), r = vec3(0.0f);
  const float side = params.volume.w * params.trace.x;
  if (params.mode.y != 0 && (is_virtual || dvct_near_region(p, 0.25f * side))) {
    if (is_virtual) {
      const DvctGather d = dvct_diffuse(p, n, VCT_LIGHT);
      rv = alb.rgb * (1.0f - alb.a) * (1.0f / MRGI_PI) * d.with;
      rv += dvct_specular(p, n, view, mix(vec3(0.04f), alb.rgb, alb.a), nrm.w, VCT_LIGHT).with;
    } else {
      const DvctGather d = dvct_diffuse(p, n, VCT_LIGHT | VCT_WITHOUT);
      rv = alb.rgb * (1.0f / MRGI_PI) * d.with;
      r = alb.rgb * (1.0f / MRGI_PI) * d.without;
      const vec2 rm = dvct_real_material(p);
      const DvctSpecular s = dvct_specular(p, dvct_mirror_normal(pixel, n), view, mix(vec3(0.04f), alb.rgb, rm.y), rm.x,
                                             VCT_LIGHT | VCT_WITHOUT);
      rv += s.with;
      r += s.without;
    }
  }
  // Half floats end at 65504 (and a NaN would spread through the up-sampling).
  rv = clamp(sanitize(rv), vec3(-60000.0f), vec3(60000.0f));
  r = clamp(sanitize(r), vec3(-60000.0f), vec3(60000.0f));
  imageStore(indirect, texel, pack_indirect(rv, r, n, max(distance(p, frame.camera_world.xyz), 1e-3f), is_virtual));
}
