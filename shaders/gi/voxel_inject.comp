#version 450
// Light injection into a voxel light volume (gi/voxel_light.h; DVCT Sec. 3.2: "render a
// reflective shadow map ... and insert all fragments into the voxel volume via a simple
// transformation"): one invocation per texel of a reflective shadow map, whose reflected flux
// P (W) is summed into the voxel holding the texel's surface, with float atomics. The resolve
// divides by pi s^2 (s the voxel size): a diffuse surface filling a voxel's cross-section with
// exitance M sends radiance M / pi, and P summed over the voxel is M s^2; a surface covering
// part of it gives that part of the radiance, i.e. radiance premultiplied by coverage, which
// the mip chain's mean and vct_math.h vct_accumulate take as they are.
//   single map: `sign` x every texel with a surface (position w 1 real, 2 virtual);
//   delta pair: this map with `sign` and `other` with -sign, only where the two maps hold
//     different surfaces (R^rho is R^mu's copy with the virtual objects drawn over it,
//     gi/rsm.h: texels they share cancel exactly). With R^rho +1 and R^mu -1 this is the
//     paper's delta light volume, "scene + object minus scene only", negative where the object
//     hides a real surface from the lamp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require

layout(local_size_x = 8, local_size_y = 8) in;
layout(constant_id = 0) const int kDeltaPair = 0;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D rsm_position;  // xyz world m, w 1 real, 2 virtual, 0 none
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D rsm_flux;      // rgb reflected W
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D other_position;  // delta pair: the other map
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D other_flux;
layout(set = 0, binding = 4, r32f) uniform imageBuffer cells;  // 3 floats a cell: flux rgb (W)
layout(push_constant) uniform InjectParams {
  vec4 region;  // xyz: the volume's min corner (m); w: voxel size (m)
  ivec4 sizes;  // x: cells per side; y, z: the map's used width and height
  vec4 sign;    // x: +1 or -1
} params_block;

#include "gi/voxel_flux.glsl"

void main() {
  const vec4 region = params_block.region;  // copied first: MRGI_UNIFORM_COPIES
  const ivec4 sizes = params_block.sizes;
  const float sign = params_block.sign.x;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= sizes.y || p.y >= sizes.z) return;
  const vec4 pos = imageLoad(rsm_position, p);
  if (kDeltaPair != 0) {
    const vec4 other = imageLoad(other_position, p);
    if (other == pos) return;  // the same surface in both maps
    if (other.w > 0.5) add_flux(other.xyz, -sign * imageLoad(other_flux, p).xyz, region, sizes.x);
  }
  if (pos.w > 0.5) add_flux(pos.xyz, sign * imageLoad(rsm_flux, p).xyz, region, sizes.x);
}
