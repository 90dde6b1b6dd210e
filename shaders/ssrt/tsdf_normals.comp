#version 460
// ssrt_tsdf_normals: N_v of the paper's G_v (Fig. 2c), the TSDF gradient (world, unit, w = 1) at
// the surface point ssrt_tsdf_raycast found for each pixel (depth D_v); (0, 0, 0, 0) where there
// is none or a neighbour sample is unobserved. A pass of its own so the frame graph drops it
// when nothing reads N_v: the ssrt G-buffer takes its normals from the filtered depth
// (depth_gbuffer.comp), and the six trilinear samples here (48 voxel loads a pixel) were about a
// third of the ray cast's time on lavapipe.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"
#include "common/frame_constants.glsl"
#include "ssrt/tsdf_volume.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform VolumeUbo { SsrtVolumeParams volume_ubo; };
SsrtVolumeParams volume;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer voxels;  // tsdf_volume.glsl
layout(set = 0, binding = 3, r32f) readonly uniform image2D depth_volume;
layout(set = 0, binding = 4, rgba16f) writeonly uniform image2D normal_volume;

#include "ssrt/tsdf_march.glsl"

void main() {
  frame = frame_ubo; volume = volume_ubo;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = spread_invocation_id();
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  float depth = imageLoad(depth_volume, pixel).x;
  vec4 normal = vec4(0.0f);
  if (depth > 0.0f) {
    // The ray cast's point: camera ray at z = 1 scaled to the depth (t = depth * |ray|).
    vec3 ray_camera = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);
    vec3 o = volume.camera_to_world[3].xyz;
    vec3 p = o + mat3(volume.camera_to_world) * ray_camera * depth;
    vec3 n;
    if (tsdf_normal(p, n)) normal = vec4(n, 1.0f);
  }
  imageStore(normal_volume, pixel, normal);
}
