#version 460
// Shadow map of the real scene as the depth camera sees it (DIR paper section 4.3): a grid mesh
// with one vertex per G-buffer pixel (or per stride-th pixel), two triangles per 2x2 block, drawn without buffers
// (gl_VertexIndex -> triangle -> pixels). A triangle with an invalid vertex or spanning a depth
// discontinuity (MRGI_DEPTH_EDGE_RELATIVE) is dropped: all three of its vertices are sent to
// the same point behind the near plane, so it has no area and is clipped.
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(set = 0, binding = 0) uniform sampler2D real_position;  // xyz world, w depth (0 invalid)
layout(push_constant) uniform Face {
  mat4 view_proj;
  ivec4 grid;  // x, y: grid vertices per row / column; z: G-buffer pixels between vertices;
               // w: G-buffer width, height packed as w = width (height is not needed)
} face;

void main() {
  int tri = gl_VertexIndex / 3;
  int corner = gl_VertexIndex - tri * 3;
  int quad = tri / 2;
  int cols = max(face.grid.x - 1, 1);
  ivec2 q = ivec2(quad % cols, quad / cols);
  ivec2 c[3];
  if ((tri & 1) == 0) { c[0] = q; c[1] = q + ivec2(1, 0); c[2] = q + ivec2(0, 1); }
  else { c[0] = q + ivec2(1, 0); c[1] = q + ivec2(1, 1); c[2] = q + ivec2(0, 1); }
  // A stride > 1 (lower quality levels) takes every stride-th G-buffer pixel as a vertex.
  int stride = max(face.grid.z, 1);
  vec4 p0 = texelFetch(real_position, c[0] * stride, 0);
  vec4 p1 = texelFetch(real_position, c[1] * stride, 0);
  vec4 p2 = texelFetch(real_position, c[2] * stride, 0);
  float zmin = min(p0.w, min(p1.w, p2.w));
  float zmax = max(p0.w, max(p1.w, p2.w));
  bool valid = zmin > 0.0f && (zmax - zmin) <= MRGI_DEPTH_EDGE_RELATIVE * zmin;
  vec4 p = corner == 0 ? p0 : (corner == 1 ? p1 : p2);
  gl_Position = valid ? face.view_proj * vec4(p.xyz, 1.0f) : vec4(0.0f, 0.0f, -2.0f, 1.0f);
}
