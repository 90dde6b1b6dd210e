#version 460
// The virtual objects' own light injected into a voxel light volume (gi/voxel_light.h,
// VoxelLight::add_inject_surfaces): the light their surfaces send that no reflective shadow map
// holds, the ambient (the light stage's SH irradiance on the surface's normal x its diffuse
// albedo) and their emission. One invocation a triangle of one draw range, cut into samples as
// the visibility voxeliser cuts it (voxelize_splat.glsl), so the light lands in the voxels the
// surface occupies; each sample adds its flux, exitance x area (W), into its voxel, which the
// resolve turns into radiance x coverage like a map's texels (voxel_inject.comp).
// Why: under an environment (no lamp) the light volume holds nothing on the objects, and a cone
// that meets one (a glossy floor's reflection of a white ball) would see it black.
// The ambient is not shadowed by the object itself here (its underside takes the ambient's
// lower hemisphere as it is): the cones that read this volume bring their own visibility.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
#include "shared/mrgi_shared.h"
#include "common/light_set.glsl"
#include "common/scene_materials.glsl"
#include "common/surface_shading.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Vertices { float vertices[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = 2) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 3) uniform sampler2DArray base_color_maps;
layout(std140, set = 0, binding = 4) uniform LightUbo { LightSet light_set; };
layout(set = 0, binding = 5, r32f) uniform imageBuffer cells;  // 3 floats a cell: flux rgb (W)
layout(push_constant) uniform SurfaceParams {
  vec4 region;      // xyz: the volume's min corner (m); w: voxel size (m)
  ivec4 range;      // x: cells per side; y: first index; z: triangles; w: vertex offset
  ivec4 material;   // x: the range's material; y: 1 add its emission; z, w unused
} params_block;

#include "gi/voxel_flux.glsl"

vec3 vertex_position(uint v) { return vec3(vertices[8 * v + 0], vertices[8 * v + 1], vertices[8 * v + 2]); }
vec3 vertex_normal(uint v) { return vec3(vertices[8 * v + 3], vertices[8 * v + 4], vertices[8 * v + 5]); }
vec2 vertex_uv(uint v) { return vec2(vertices[8 * v + 6], vertices[8 * v + 7]); }

// The triangle being cut (its vertices' normals and texture coordinates) and what every one of
// its samples shares.
vec3 tri_n0, tri_n1, tri_n2;
vec2 tri_uv0, tri_uv1, tri_uv2;
GpuMaterial tri_material;
AmbientIrradiance tri_ambient;
bool tri_emits;

void inject_sample(vec3 world, vec2 bary, vec3 g, float sub_area_voxels, vec4 region, int n) {
  const float w0 = 1.0 - bary.x - bary.y;
  vec3 normal = tri_n0 * w0 + tri_n1 * bary.x + tri_n2 * bary.y;
  normal = dot(normal, normal) > 1e-12 ? normalize(normal) : g;
  const vec2 uv = tri_uv0 * w0 + tri_uv1 * bary.x + tri_uv2 * bary.y;
  vec3 exitance = material_diffuse_albedo(tri_material, base_color_maps, uv) * ambient_irradiance(tri_ambient, normal);
  if (tri_emits) {
    vec3 emission = tri_material.emission.rgb;
    if (tri_material.emission.w >= 0.0) emission *= textureLod(base_color_maps, vec3(uv, tri_material.emission.w), 0.0).rgb;
    exitance += MRGI_PI * emission;  // a Lambertian emitter of radiance L sends pi L per m^2
  }
  add_flux(world, exitance * (sub_area_voxels * region.w * region.w), region, n);
}

#define MRGI_SPLAT_VISIT(world, bary, g, sub_area) inject_sample(world, bary, g, sub_area, region, n)
#include "gi/voxelize_splat.glsl"

void main() {
  const vec4 region = params_block.region;  // copied first: MRGI_UNIFORM_COPIES
  const ivec4 range = params_block.range;
  const ivec4 material = params_block.material;
  const int t = int(gl_GlobalInvocationID.x);
  if (t >= range.z) return;
  const uint base = uint(range.y + 3 * t);
  const uint i0 = uint(int(indices[base + 0u]) + range.w);
  const uint i1 = uint(int(indices[base + 1u]) + range.w);
  const uint i2 = uint(int(indices[base + 2u]) + range.w);
  tri_n0 = vertex_normal(i0);
  tri_n1 = vertex_normal(i1);
  tri_n2 = vertex_normal(i2);
  tri_uv0 = vertex_uv(i0);
  tri_uv1 = vertex_uv(i1);
  tri_uv2 = vertex_uv(i2);
  tri_material = materials[material.x];
  tri_ambient = light_set.ambient_rv;
  tri_emits = material.y != 0;
  splat_triangle(vertex_position(i0), vertex_position(i1), vertex_position(i2), tri_n0 + tri_n1 + tri_n2, region, range.x);
}
