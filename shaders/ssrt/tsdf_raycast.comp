#version 460
// ssrt_tsdf_raycast: the volume's view of this frame's camera at the internal resolution (the
// paper's G_v, Fig. 2c: D_v here, N_v in tsdf_normals.comp). Per pixel the camera ray is marched
// through the TSDF to its first front-facing zero crossing (tsdf_march.glsl); D_v = that
// point's depth along the camera z in metres. No crossing: 0.
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
layout(set = 0, binding = 3, r32f) writeonly uniform image2D depth_volume;

#include "ssrt/tsdf_march.glsl"

void main() {
  frame = frame_ubo; volume = volume_ubo;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = spread_invocation_id();
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  vec3 ray_camera = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);  // z = 1
  vec3 o = volume.camera_to_world[3].xyz;
  vec3 d_unnormalised = mat3(volume.camera_to_world) * ray_camera;
  float len = length(d_unnormalised);
  vec3 d = d_unnormalised / len;
  float t = tsdf_march(o, d, 0.0f);
  float depth = t > 0.0f ? t / len : 0.0f;  // the ray has camera z = 1 per `len` metres
  imageStore(depth_volume, pixel, vec4(depth, 0.0f, 0.0f, 0.0f));
}
