#version 460
// Shadow map of the real scene as the depth camera sees it (DIR paper section 4.3): one vertex
// per point of a grid over the G-buffer (every stride-th pixel), drawn indexed with the indices
// shadow_caster_indices.comp wrote this frame (it drops triangles with an invalid vertex or
// across a depth discontinuity, so a vertex without depth is never part of a drawn triangle).
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(set = 0, binding = 0) uniform sampler2D real_position;  // xyz world, w depth (0 invalid)
layout(push_constant) uniform Face {
  mat4 view_proj;
  ivec4 grid;  // x, y: grid points per row / column; z: G-buffer pixels between points
} face;

void main() {
  int row = max(face.grid.x, 1);
  ivec2 g = ivec2(gl_VertexIndex % row, gl_VertexIndex / row);
  vec4 p = texelFetch(real_position, g * max(face.grid.z, 1), 0);
  gl_Position = face.view_proj * vec4(p.xyz, 1.0f);
}
