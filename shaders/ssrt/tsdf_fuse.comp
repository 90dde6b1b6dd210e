#version 460
// ssrt_tsdf_fuse: KinectFusion's projective TSDF update (Newcombe et al. 2011 Sec. 3.3, the ssrt
// paper's ref. [21]) of this frame's raw depth D_c into the volume V. One invocation per voxel
// column (x, y), walking z: each voxel centre is projected into the depth camera (nearest
// pixel), sdf = D_c(u) - z_voxel along the camera's z; voxels with no measurement, behind the
// camera, outside the image or farther than mu behind the surface keep their value; the rest get
// tsdf = min(1, sdf / mu) folded into the running average, weight capped at the settings' cap
// (so the volume can still follow slow scene changes).
#extension GL_GOOGLE_include_directive : require
#include "ssrt/tsdf_volume.glsl"
#include "common/opaque_uniform.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform VolumeUbo { SsrtVolumeParams volume_ubo; };
SsrtVolumeParams volume;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
layout(std430, set = 0, binding = 2) buffer Voxels { uint voxels[]; };

uint depth_value(uint index) { return (imageLoad(depth_words, int(index >> 1)).x >> ((index & 1u) * 16u)) & 0xffffu; }

void main() {
  volume = volume_ubo;  // MRGI_UNIFORM_COPIES
  int r = MRGI_OPAQUE_INT(volume.grid.x);  // the loop bound (common/opaque_uniform.glsl)
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(xy, ivec2(r)))) return;
  float h = volume.origin.w, mu = volume.tsdf.x, max_weight = volume.tsdf.y;
  float units = volume.tsdf.z;
  ivec2 depth_size = volume.grid.yz;
  vec4 k = volume.depth_k;
  // Camera-space position of the column's first voxel centre and the step per voxel along z.
  vec3 first = volume.origin.xyz + (vec3(xy, 0.0f) + 0.5f) * h;
  vec3 p0 = (volume.world_to_camera * vec4(first, 1.0f)).xyz;
  vec3 dz = mat3(volume.world_to_camera) * vec3(0.0f, 0.0f, h);
  uint index = uint(xy.x + r * xy.y);
  uint slice = uint(r * r);
  for (int z = 0; z < r; ++z, index += slice) {
    vec3 p = p0 + float(z) * dz;
    if (!(p.z > 1e-3f)) continue;
    vec2 uv = vec2(k.x * p.x / p.z + k.z, k.y * p.y / p.z + k.w);
    ivec2 px = ivec2(floor(uv + 0.5f));
    if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, depth_size))) continue;
    uint raw = depth_value(uint(px.x + depth_size.x * px.y));
    if (raw == 0u) continue;
    float sdf = float(raw) / units - p.z;
    if (sdf < -mu) continue;
    float tsdf = min(1.0f, sdf / mu);
    vec2 old = unpackHalf2x16(voxels[index]);
    float w = old.y;
    float fused = (old.x * w + tsdf) / (w + 1.0f);
    voxels[index] = packHalf2x16(vec2(fused, min(w + 1.0f, max_weight)));
  }
}
