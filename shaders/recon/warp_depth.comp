#version 460
// Temporal depth filter, step 1 (DIR paper section 4.2, eq. 11-14): the previous frame's
// filtered depth is forward-projected into the current view as the paper's grid mesh. Each
// previous pixel is the top-left corner of a grid cell of two triangles (itself, its right,
// lower and lower-right neighbours); their corners are back-projected (eq. 11), moved by the
// pose change previous camera -> current camera (eq. 12, 13; computed on the CPU in double
// precision) and projected (eq. 14), and every current pixel whose centre a triangle covers gets
// the triangle's inverse depth interpolated there (inverse depth is affine in screen space on a
// plane) - what rasterising the mesh does. Overlaps are resolved by an atomicMin on the packed
// (depth, weight) word: the z-test between surfaces. A triangle with a missing corner or across
// a depth discontinuity (the normals' depth-edge rule) is not drawn: pixels nobody covers stay
// empty and take the new depth alone in the merge.
// Why triangles and not each point splatted with a plane through it and two neighbours: that
// plane is extrapolated to pixels outside the point's own triangle, and on quantised depth (a
// Kinect's disparity steps) a staircase's step extrapolates to a wrong depth; with the camera
// moving every frame, the history's error then grew from frame to frame instead of averaging
// out (tests/technique/recon_filter_test.cpp, SlidingCameraDoesNotDriftTheSurface: 5-7 mm rms
// growing to 14-22 mm over 24 frames; on the suite's desk_spot the floor came out rippled and
// shadowed itself in the real casters' shadow map). Inside its triangle the interpolation is a
// convex combination of the corners: it cannot leave their range.
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

// Corner `pixel` of a grid cell: its previous filtered depth and weight, warped to
// (screen x, y, 1/z); false if it has no depth or lands behind the camera.
bool warped_corner(ivec2 pixel, out vec3 s, out vec2 zw) {
  s = vec3(0.0f);
  zw = imageLoad(previous_depth, pixel).xy;
  if (!(zw.x > 0.0f) || !(zw.y >= 1.0f) || isinf(zw.x)) return false;
  vec3 q = warp_point(pixel, zw.x);
  if (!(q.z > 1e-3f) || !(q.z < MRGI_WARP_MAX_DEPTH)) return false;
  s = vec3(project_pinhole(q, frame.internal_k), 1.0f / q.z);
  return true;
}

bool same_surface(float a, float b) { return abs(a - b) <= MRGI_DEPTH_EDGE_RELATIVE * min(a, b); }

// A triangle's side of its largest extent, in pixels, beyond which it is not drawn: a grid cell
// grows that much only when the camera moves towards the surface by that factor in one frame.
const float kMaxTriangleSpan = 6.0f;
// Pixels (and barycentric units, triangles being about a pixel across): a rounding margin.
const float kSnap = 1e-3f;

// Writes the triangle (a, b, c) (screen x, y, 1/z) into every current pixel whose centre it
// covers, with the corners' weights (wa, wb, wc) interpolated there too: a pixel that lands on a
// corner keeps that corner's weight (the smallest of the three would spread one pixel's fresh
// start to its neighbours, frame after frame).
void draw_triangle(vec3 a, vec3 b, vec3 c, vec3 weights, ivec2 size) {
  vec2 lo = min(a.xy, min(b.xy, c.xy)), hi = max(a.xy, max(b.xy, c.xy));
  if (any(greaterThan(hi - lo, vec2(kMaxTriangleSpan)))) return;
  vec2 e1 = b.xy - a.xy, e2 = c.xy - a.xy;
  float det = e1.x * e2.y - e1.y * e2.x;
  if (abs(det) < 1e-6f) return;  // edge-on
  // Centres within kSnap of the triangle count (on an edge: for both triangles there, which hold
  // the same depth along it). Without the margin a corner pixel of the image's first row or
  // column that projects a rounding error past its own centre would be left out of every
  // triangle and lose its history now and then.
  ivec2 t0 = max(ivec2(ceil(lo - kSnap)), ivec2(0)), t1 = min(ivec2(floor(hi + kSnap)), size - 1);
  const float eps = -kSnap;
  for (int y = t0.y; y <= t1.y; ++y) {
    for (int x = t0.x; x <= t1.x; ++x) {
      vec2 d = vec2(x, y) - a.xy;
      float beta = (d.x * e2.y - d.y * e2.x) / det;
      float gamma = (e1.x * d.y - e1.y * d.x) / det;
      if (beta < eps || gamma < eps || beta + gamma > 1.0f - eps) continue;
      // A centre within kSnap of a corner takes that corner as it is (a camera that did not move
      // warps every pixel onto itself, and the history must stay bit-exact: interpolating there
      // would mix in the neighbours by rounding).
      if (beta < kSnap && gamma < kSnap) beta = gamma = 0.0f;
      else if (beta > 1.0f - kSnap && gamma < kSnap) { beta = 1.0f; gamma = 0.0f; }
      else if (gamma > 1.0f - kSnap && beta < kSnap) { beta = 0.0f; gamma = 1.0f; }
      float inv_z = a.z + beta * (b.z - a.z) + gamma * (c.z - a.z);
      if (!(inv_z > 0.0f)) continue;
      float z = 1.0f / inv_z;
      if (!(z < MRGI_WARP_MAX_DEPTH)) continue;
      float weight = weights.x + beta * (weights.y - weights.x) + gamma * (weights.z - weights.x);
      imageAtomicMin(warped, ivec2(x, y), pack_warped(z, weight));
    }
  }
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel + 1, size))) return;  // the last row and column start no cell
  vec3 s00, s10, s01, s11;
  vec2 w00, w10, w01, w11;
  bool v00 = warped_corner(pixel, s00, w00);
  bool v10 = warped_corner(pixel + ivec2(1, 0), s10, w10);
  bool v01 = warped_corner(pixel + ivec2(0, 1), s01, w01);
  bool v11 = warped_corner(pixel + ivec2(1, 1), s11, w11);
  if (v10 && v01) {
    bool b01 = same_surface(w10.x, w01.x);
    if (v00 && b01 && same_surface(w00.x, w10.x) && same_surface(w00.x, w01.x))
      draw_triangle(s00, s10, s01, vec3(w00.y, w10.y, w01.y), size);
    if (v11 && b01 && same_surface(w11.x, w10.x) && same_surface(w11.x, w01.x))
      draw_triangle(s10, s11, s01, vec3(w10.y, w11.y, w01.y), size);
  }
}
