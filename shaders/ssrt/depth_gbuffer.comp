#version 460
// ssrt depth filter, last pass: the filtered depth (D''', or D'' without the final pass) ->
// the technique's real G-buffer: world positions (internal_k unprojection, then the frame's
// camera_to_world) and normals from neighbouring positions, with the same rule as
// recon/normals.comp: tangents as central differences over +-r texels (push constant) where both
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
#include "common/workgroup_order.glsl"
#include "common/frame_constants.glsl"
#include "ssrt/depth_median.glsl"

// x: tangent radius in texels (recon's default normal_radius, 2 px, shrunk with the texel size
// so the tangents span the same part of the scene: a crease blends normals over the radius).
struct PushConstants { ivec4 normal; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32f) readonly uniform image2D depth;       // metres, 0 = none
layout(set = 0, binding = 2, rgba32f) writeonly uniform image2D position;
layout(set = 0, binding = 3, rgba16f) writeonly uniform image2D normal;

ivec2 g_size;

// Depth at pixel p if inside the image, valid and on the centre's surface (depth z0), else 0.
// Fetched unconditionally from a clamped coordinate: the lanes of a SIMD chunk stay together.
float same_surface(ivec2 p, float z0) {
  bool inside = all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, g_size));
  float z = imageLoad(depth, clamp(p, ivec2(0), g_size - 1)).x;
  bool ok = inside && depth_valid(z) && abs(z - z0) <= MRGI_DEPTH_EDGE_RELATIVE * min(z, z0);
  return ok ? z : 0.0f;
}

vec3 camera_point(ivec2 p, float z) { return unproject_pinhole(vec2(p), z, frame.internal_k); }

// Tangent along one image axis: central over +-r texels where both ends are on the
// surface, else forward, else backward one pixel. The one-pixel fetches only happen where the
// central difference fails (depth edges, holes), which whole SIMD chunks rarely need.
bool axis_difference(ivec2 p, ivec2 step, vec3 centre, float z0, out vec3 d) {
  float far_plus = same_surface(p + step * pc.normal.x, z0);
  float far_minus = same_surface(p - step * pc.normal.x, z0);
  d = camera_point(p + step * pc.normal.x, far_plus) -
      camera_point(p - step * pc.normal.x, far_minus);
  if (far_plus > 0.0f && far_minus > 0.0f) return true;
  float plus = same_surface(p + step, z0);
  float minus = same_surface(p - step, z0);
  d = plus > 0.0f ? camera_point(p + step, plus) - centre : centre - camera_point(p - step, minus);
  return plus > 0.0f || minus > 0.0f;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  g_size = frame.internal_output_size.xy;
  ivec2 pixel = spread_invocation_id();
  if (any(greaterThanEqual(pixel, g_size))) return;
  float z0 = imageLoad(depth, pixel).x;
  if (!depth_valid(z0)) {
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
  if (axis_difference(pixel, ivec2(1, 0), centre, z0, dx) &&
      axis_difference(pixel, ivec2(0, 1), centre, z0, dy)) {
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
