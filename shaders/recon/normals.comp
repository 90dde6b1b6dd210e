#version 460
// Reconstruction step 3: normals from neighbouring (temporally filtered) world positions, the
// DIR paper's cross product of two tangents (section 4.2):
//   N(u,v) = (V(u+1,v) - V(u,v)) x (V(u,v+1) - V(u,v)),
// with the tangents taken as central differences over +-radius pixels where both ends lie on
// the centre's surface. Why the wider stencil: the angular error of a difference tangent is
// depth noise / baseline, so a 2r-pixel baseline cuts it by 2r at the cost of rounding normals
// within r pixels of a crease. Where that fails the one-pixel forward difference is used, then
// the backward one (V(u,v) - V(u-1,v)); with none, the normal faces the camera. Normals are
// oriented towards the camera (a surface seen by the camera faces it).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 2, rgba16f) writeonly uniform image2D real_normal;  // xyz, w valid
struct PushConstants { ivec4 stencil; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;  // x: central-difference radius >= 1

ivec2 g_size;

// Position of a neighbour if it is valid and on the same surface as the centre (depth z0).
bool neighbour(ivec2 p, float z0, out vec3 pos) {
  pos = vec3(0.0f);
  if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, g_size))) return false;
  vec4 v = imageLoad(real_position, p);
  if (!(v.w > 0.0f)) return false;
  if (abs(v.w - z0) > MRGI_DEPTH_EDGE_RELATIVE * min(v.w, z0)) return false;
  pos = v.xyz;
  return true;
}

// Difference along one image axis: central over +-radius if possible, else forward, else
// backward.
bool axis_difference(ivec2 pixel, ivec2 step, vec4 centre, out vec3 d) {
  vec3 q, r;
  d = vec3(0.0f);
  int radius = max(pc.stencil.x, 1);
  if (radius > 1 && neighbour(pixel + step * radius, centre.w, q) &&
      neighbour(pixel - step * radius, centre.w, r)) {
    d = q - r;
    return true;
  }
  if (neighbour(pixel + step, centre.w, q)) { d = q - centre.xyz; return true; }
  if (neighbour(pixel - step, centre.w, q)) { d = centre.xyz - q; return true; }
  return false;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  g_size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, g_size))) return;
  vec4 centre = imageLoad(real_position, pixel);
  if (!(centre.w > 0.0f)) {
    imageStore(real_normal, pixel, vec4(0.0f));
    return;
  }
  vec3 to_camera = normalize(frame.camera_world.xyz - centre.xyz);
  vec3 dx, dy;
  vec3 n = to_camera;
  if (axis_difference(pixel, ivec2(1, 0), centre, dx) &&
      axis_difference(pixel, ivec2(0, 1), centre, dy)) {
    vec3 c = cross(dx, dy);
    float len = length(c);
    if (len > 1e-12f && !isnan(len) && !isinf(len)) n = c / len;
  }
  if (dot(n, to_camera) < 0.0f) n = -n;
  imageStore(real_normal, pixel, vec4(n, 1.0f));
}
