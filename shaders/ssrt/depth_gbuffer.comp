#version 460
// ssrt depth filter, last pass: the filtered depth (D''', or D'' without the final pass) ->
// the technique's real G-buffer: world positions (internal_k unprojection, then the frame's
// camera_to_world) and normals from neighbouring positions, with the same rule as
// recon/normals.comp: tangents as central differences over +-NORMAL_RADIUS pixels where both
// ends lie on the centre's surface (the MRGI_DEPTH_EDGE_RELATIVE rule), else the one-pixel
// forward, else the backward difference; oriented towards the camera. The cross product is
// taken in camera space and rotated to world (a rotation keeps it). Where an axis has no
// same-surface neighbour at all (a depth edge on both sides, an isolated pixel) the normal is
// not measured: w = 0, xyz = the direction to the camera, so a reader that ignores w still
// gets a sane facing normal.
// Outputs: position RGBA32F (xyz world, w depth m; all 0 = invalid), normal RGBA16F (xyz unit,
// w 1 measured / 0 not; all 0 where the position is invalid).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require  // depth_median.glsl
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

#define GROUP 16
#define NORMAL_RADIUS 2                    // pixels, as recon's default normal_radius
#define TILE_W (GROUP + 2 * NORMAL_RADIUS)

layout(local_size_x = GROUP, local_size_y = GROUP) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) readonly uniform image2D depth;       // metres, 0 = none
layout(set = 0, binding = 2, rgba32f) writeonly uniform image2D position;
layout(set = 0, binding = 3, rgba16f) writeonly uniform image2D normal;

shared float s_z[TILE_W * TILE_W];  // depth, 0 = invalid or outside the image

ivec2 g_tile_origin;

// Camera-space position of tile texel t if valid and on the centre's surface (depth z0).
bool neighbour(ivec2 t, float z0, out vec3 pos) {
  pos = vec3(0.0f);
  float z = s_z[t.y * TILE_W + t.x];
  if (!(z > 0.0f)) return false;
  if (abs(z - z0) > MRGI_DEPTH_EDGE_RELATIVE * min(z, z0)) return false;
  pos = unproject_pinhole(vec2(g_tile_origin + t), z, frame.internal_k);
  return true;
}

bool axis_difference(ivec2 t, ivec2 step, vec3 centre, float z0, out vec3 d) {
  vec3 q, r;
  d = vec3(0.0f);
  if (neighbour(t + step * NORMAL_RADIUS, z0, q) && neighbour(t - step * NORMAL_RADIUS, z0, r)) {
    d = q - r;
    return true;
  }
  if (neighbour(t + step, z0, q)) { d = q - centre; return true; }
  if (neighbour(t - step, z0, q)) { d = centre - q; return true; }
  return false;
}

void main() {
  ivec2 size = frame.internal_output_size.xy;
  g_tile_origin = ivec2(gl_WorkGroupID.xy) * GROUP - NORMAL_RADIUS;
  for (int i = int(gl_LocalInvocationIndex); i < TILE_W * TILE_W; i += GROUP * GROUP) {
    ivec2 q = g_tile_origin + ivec2(i % TILE_W, i / TILE_W);
    float z = 0.0f;
    if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))) {
      z = imageLoad(depth, q).x;
      if (!depth_valid(z)) z = 0.0f;
    }
    s_z[i] = z;
  }
  barrier();

  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, size))) return;
  ivec2 t = ivec2(gl_LocalInvocationID.xy) + NORMAL_RADIUS;
  float z0 = s_z[t.y * TILE_W + t.x];
  if (!(z0 > 0.0f)) {
    imageStore(position, pixel, vec4(0.0f));
    imageStore(normal, pixel, vec4(0.0f));
    return;
  }
  vec3 centre = unproject_pinhole(vec2(pixel), z0, frame.internal_k);
  vec4 world = frame.camera_to_world * vec4(centre, 1.0f);
  imageStore(position, pixel, vec4(world.xyz, z0));

  vec3 to_camera = normalize(-centre);  // camera space: the camera is the origin
  vec3 n = to_camera;
  float measured = 0.0f;
  vec3 dx, dy;
  if (axis_difference(t, ivec2(1, 0), centre, z0, dx) &&
      axis_difference(t, ivec2(0, 1), centre, z0, dy)) {
    vec3 c = cross(dx, dy);
    float len = length(c);
    if (len > 1e-12f && !isnan(len) && !isinf(len)) {
      n = c / len;
      measured = 1.0f;
    }
  }
  if (dot(n, to_camera) < 0.0f) n = -n;
  vec3 n_world = normalize(mat3(frame.camera_to_world) * n);
  imageStore(normal, pixel, vec4(n_world, measured));
}
