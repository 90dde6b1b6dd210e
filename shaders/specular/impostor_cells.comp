#version 460
// The real grid's triangles each impostor face of a set draws (specular/specular.h): the grid of
// shading/shadow_caster_indices.comp (a point every `stride` G-buffer pixels, two triangles a
// cell, none across a depth edge), each triangle appended to the index list of every cube face
// one of its vertices falls in, seen from the set's centre. Drawing the whole grid into each of
// the six faces made lavapipe set up six times the triangles it rasterised (4 of a set's 5 ms at
// glass_mirror's fast level); a triangle lands in one face, at most three.
// Lists: face f's indices start at f * capacity; draws[f].index_count counts them (reset to 0
// before this pass; instance_count and first_index are written here).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D real_position;  // xyz world, w depth (0 invalid)
layout(std430, set = 0, binding = 1) writeonly buffer FaceIndices { uint face_indices[]; };
struct DrawIndexedIndirect {
  uint index_count, instance_count, first_index;
  int vertex_offset;
  uint first_instance;
};
layout(std430, set = 0, binding = 2) buffer FaceDraws { DrawIndexedIndirect draws[6]; };
layout(push_constant) uniform Cells {
  ivec4 grid;    // x, y grid points per row / column; z G-buffer pixels between points; w capacity
  vec4 centre;   // xyz the set's centre
};

int face_of(vec3 p) { return int(specular_cube_face(p - centre.xyz).z); }

void append(uint faces, uint a, uint b, uint c) {
  for (int f = 0; f < 6; ++f) {
    if ((faces & (1u << uint(f))) == 0u) continue;
    uint at = atomicAdd(draws[f].index_count, 3u);
    if (at + 3u > uint(grid.w)) continue;  // never: a face holds at most every triangle
    uint base = uint(f) * uint(grid.w) + at;
    face_indices[base] = a;
    face_indices[base + 1u] = b;
    face_indices[base + 2u] = c;
  }
}

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  if (q == ivec2(0)) {
    for (int f = 0; f < 6; ++f) {
      draws[f].instance_count = 1u;
      draws[f].first_index = uint(f) * uint(grid.w);
      draws[f].vertex_offset = 0;
      draws[f].first_instance = 0u;
    }
  }
  ivec2 cells = grid.xy - 1;
  if (any(greaterThanEqual(q, cells))) return;
  int stride = grid.z;
  vec4 p00 = texelFetch(real_position, q * stride, 0);
  vec4 p10 = texelFetch(real_position, (q + ivec2(1, 0)) * stride, 0);
  vec4 p01 = texelFetch(real_position, (q + ivec2(0, 1)) * stride, 0);
  vec4 p11 = texelFetch(real_position, (q + ivec2(1, 1)) * stride, 0);
  uint row = uint(grid.x);
  uint i00 = uint(q.y) * row + uint(q.x), i10 = i00 + 1u, i01 = i00 + row, i11 = i01 + 1u;
  uint f00 = 1u << uint(face_of(p00.xyz)), f10 = 1u << uint(face_of(p10.xyz));
  uint f01 = 1u << uint(face_of(p01.xyz)), f11 = 1u << uint(face_of(p11.xyz));
  if (mrgi_one_surface(p00.w, p10.w, p01.w)) append(f00 | f10 | f01, i00, i10, i01);
  if (mrgi_one_surface(p10.w, p11.w, p01.w)) append(f10 | f11 | f01, i10, i11, i01);
}
