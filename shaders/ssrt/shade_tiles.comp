#version 460
// ssrt fast levels: the list of 8 x 8 pixel tiles ssrt_shade must shade, as an indirect dispatch.
// Every pixel first gets the pass-through solution (L_r = L_rv, the compose returns the camera
// colour); a tile is shaded properly only when its result can differ from that: some cell of its
// bicubic footprint has R'_d != R_d or R'_i != R_i (compared bit for bit after the Gauss filter:
// where nothing virtual took part the two solutions are identical, transfer.comp), or the tile
// meets the virtual objects' projected bounds (their own pixels, which a 4x4 cell centre can
// miss). On lavapipe a shader runs all of its code for every invocation, so pixels that need no
// shading can only be saved by not dispatching them.
// Output: args = VkDispatchIndirectCommand (x counted here; a transfer pass sets it to (0, 1, 1)
// first), list = the tile indices (ty * tiles_x + tx) in no particular order.
#extension GL_GOOGLE_include_directive : require
#include "ssrt/upsampled.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D upsampled;
layout(std430, set = 0, binding = 1) buffer Args { uint args[4]; };  // x, y, z groups, pad
layout(std430, set = 0, binding = 2) writeonly buffer Tiles { uint list[]; };
layout(push_constant) uniform Push {
  ivec4 grid;     // x, y cells; z step in pixels
  ivec4 counts;   // x, y tiles
  ivec4 virt;     // pixels [x0, x1) x [y0, y1) of the virtual objects' projected bounds
} pc;

bool cell_differs(uvec4 p) {
  bool d = (p.x & 0x7fffu) != ((p.x >> 16) & 0x7fffu);  // R_d vs R'_d (sign bits are the kind)
  d = d || (p.y & 0xffffu) != (p.z >> 16);             // R_i.r vs R'_i.r
  d = d || (p.y >> 16) != (p.w & 0xffffu);             // R_i.g vs R'_i.g
  d = d || (p.z & 0xffffu) != (p.w >> 16);             // R_i.b vs R'_i.b
  return d || (p.x & 0x00008000u) != 0u;               // a virtual cell
}

void main() {
  int id = int(gl_GlobalInvocationID.x);
  if (id >= pc.counts.x * pc.counts.y) return;
  ivec2 tile = ivec2(id % pc.counts.x, id / pc.counts.x);
  ivec2 p0 = tile * 8, p1 = p0 + ivec2(7);
  // Cells a pixel's bicubic reads: floor((p - step/2) / step) - 1 .. + 2 (shade.comp).
  int st = pc.grid.z;
  ivec2 c0 = ivec2(floor((vec2(p0) - float(st / 2)) / float(st))) - 1;
  ivec2 c1 = ivec2(floor((vec2(p1) - float(st / 2)) / float(st))) + 2;
  c0 = clamp(c0, ivec2(0), pc.grid.xy - 1);
  c1 = clamp(c1, ivec2(0), pc.grid.xy - 1);
  bool needed = p1.x >= pc.virt.x && p0.x < pc.virt.z && p1.y >= pc.virt.y && p0.y < pc.virt.w;
  for (int y = c0.y; y <= c1.y; ++y)
    for (int x = c0.x; x <= c1.x; ++x) needed = needed || cell_differs(imageLoad(upsampled, ivec2(x, y)));
  if (needed) list[atomicAdd(args[0], 1u)] = uint(id);
}
