#version 460
// Temporal depth filter, step 1 (DIR paper section 4.2, eq. 11-14): the previous frame's
// filtered depth is forward-projected into the current view. Each previous pixel is
// back-projected (eq. 11), moved by the pose change previous camera -> current camera (eq. 12,
// 13; computed on the CPU in double precision), projected (eq. 14) and scattered to the nearest
// current pixel. Overlaps are resolved by an atomicMin on the packed (depth, weight) word, the
// compute equivalent of the paper's z-test over a grid mesh. Points behind the camera, beyond
// the packing range or outside the image are discarded; pixels nobody lands on stay empty and
// take the new depth alone in the merge (a point splat never stretches a surface across a
// disocclusion, which the paper's mesh has to reject with an edge-length test).
// The depth written is not the point's own but the surface's at the target pixel centre, from
// the plane through the point and its right and lower neighbours (inverse depth is affine in
// screen space on a plane) - what rasterising the paper's grid mesh interpolates. Without it a
// tilted floor would get up to half a pixel's depth slope of error per warp (centimetres at
// grazing angles), biased in the direction of motion.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "recon/depth_filter.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rg32f) readonly uniform image2D previous_depth;  // x z m, y weight
layout(set = 0, binding = 2, r32ui) uniform uimage2D warped;                  // packed, cleared
struct PushConstants { mat4 previous_to_current; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

vec3 warp_point(ivec2 pixel, float z) {
  vec3 p = unproject_pinhole(vec2(pixel), z, frame.internal_k);
  return (pc.previous_to_current * vec4(p, 1.0f)).xyz;
}

// Neighbour `pixel` of the previous depth warped to (screen x, y, 1/z) if it is valid and on
// the same surface as depth z0 (the normals' depth-edge rule).
bool warped_neighbour(ivec2 pixel, ivec2 size, float z0, out vec3 s) {
  s = vec3(0.0f);
  if (any(greaterThanEqual(pixel, size))) return false;
  float z = imageLoad(previous_depth, pixel).x;
  if (!(z > 0.0f) || abs(z - z0) > MRGI_DEPTH_EDGE_RELATIVE * min(z, z0)) return false;
  vec3 q = warp_point(pixel, z);
  if (!(q.z > 1e-3f)) return false;
  s = vec3(project_pinhole(q, frame.internal_k), 1.0f / q.z);
  return true;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, size))) return;
  vec2 zw = imageLoad(previous_depth, pixel).xy;
  if (!(zw.x > 0.0f) || !(zw.y >= 1.0f) || isinf(zw.x)) return;
  vec3 q = warp_point(pixel, zw.x);
  if (!(q.z > 1e-3f) || !(q.z < MRGI_WARP_MAX_DEPTH)) return;
  vec2 uv = project_pinhole(q, frame.internal_k);
  ivec2 t = ivec2(floor(uv + 0.5f));
  if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) return;
  float z = q.z;
  vec3 a, b;
  if (warped_neighbour(pixel + ivec2(1, 0), size, zw.x, a) &&
      warped_neighbour(pixel + ivec2(0, 1), size, zw.x, b)) {
    vec2 ea = a.xy - uv, eb = b.xy - uv;
    float det = ea.x * eb.y - ea.y * eb.x;
    if (abs(det) > 1e-3f) {  // not a degenerate (edge-on) triangle
      vec2 d = vec2(t) - uv;
      // d = alpha ea + beta eb; inverse depth interpolated with the same weights.
      float alpha = (d.x * eb.y - d.y * eb.x) / det;
      float beta = (ea.x * d.y - ea.y * d.x) / det;
      float inv_z = 1.0f / q.z + alpha * (a.z - 1.0f / q.z) + beta * (b.z - 1.0f / q.z);
      float zc = 1.0f / inv_z;
      // Kept only within the edge rule of the point's own depth (no extrapolation runaway).
      if (inv_z > 0.0f && abs(zc - q.z) <= MRGI_DEPTH_EDGE_RELATIVE * q.z) z = zc;
    }
  }
  if (!(z < MRGI_WARP_MAX_DEPTH)) return;
  imageAtomicMin(warped, t, pack_warped(z, zw.y));
}
