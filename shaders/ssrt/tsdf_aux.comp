#version 460
// ssrt_tsdf_aux: the auxiliary orthographic geometry buffers of paper Sec. 5.1 (left, right,
// top of the camera, and the dominant light's view), all four layers in one dispatch (y spans
// the layers). Each texel marches its parallel ray from the layer's image plane along the view
// axis through the TSDF and stores the first front-facing surface: xyz world, w depth along the
// axis (m); no surface: 0. The views and the occlusion rule are in ssrt/aux_views.glsl.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"
#include "ssrt/aux_views.glsl"
#include "ssrt/tsdf_volume.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform VolumeUbo { SsrtVolumeParams volume_ubo; };
SsrtVolumeParams volume;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform AuxUbo { SsrtAuxViews views; };
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer voxels;  // tsdf_volume.glsl
layout(set = 0, binding = 3, rgba32f) writeonly uniform image2DArray aux_position;

#include "ssrt/tsdf_march.glsl"

void main() {
  volume = volume_ubo;  // MRGI_UNIFORM_COPIES
  int res = views.info.y;
  ivec2 id = spread_invocation_id();
  int layer = div_nonneg1(id.y, res);
  ivec2 texel = ivec2(id.x, id.y - layer * res);
  if (id.x >= res || layer >= views.info.x) return;
  vec2 uv = (vec2(texel) + 0.5f) / float(res);
  vec3 o = (views.aux_to_world[layer] * vec4(uv, 0.0f, 1.0f)).xyz;
  vec3 d = views.direction[layer].xyz;
  vec4 result = vec4(0.0f);
  float t = tsdf_march(o, d, 0.0f);
  // A surface exactly on the image plane would read as "none": keep w strictly positive.
  if (t >= 0.0f) result = vec4(o + t * d, max(t, 1e-6f));
  imageStore(aux_position, ivec3(texel, layer), result);
}
