#version 460
// ssrt fast levels: the list of 8 x 8 pixel tiles ssrt_shade must shade, as an indirect dispatch.
// Every pixel first gets the pass-through solution (L_r = L_rv, the compose returns the camera
// colour); a tile is shaded properly only when its result can visibly differ from that: the
// tile meets the virtual objects' projected bounds (their own pixels, which a 4x4 cell centre
// can miss), some cell of its bicubic footprint is virtual, or the footprint's two solutions
// differ by more than the tile tolerance allows (transfer_math.h ssrt_tile_invisible: no pixel
// would move by more than one 8-bit level). Where nothing virtual took part the solutions are
// identical bit for bit (transfer.comp); much of the influence region differs by a fraction of
// a per cent (a far virtual occluder takes one sample's weight from a few cells). On lavapipe a
// shader runs all of its code for every invocation, so pixels that need no shading can only be
// saved by not dispatching them.
// Output: args = VkDispatchIndirectCommand (x counted here; a transfer pass sets it to (0, 1, 1)
// first), list = the tile indices (ty * tiles_x + tx) in no particular order.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/transfer_math.h"
#include "ssrt/upsampled.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, rgba32ui) readonly uniform uimage2D upsampled;
layout(std430, set = 0, binding = 1) buffer Args { uint args[4]; };  // x, y, z groups, pad
layout(std430, set = 0, binding = 2) writeonly buffer Tiles { uint list[]; };
struct PushConstants {
  ivec4 grid;     // x, y cells; z step in pixels
  ivec4 counts;   // x, y tiles
  ivec4 virt;     // pixels [x0, x1) x [y0, y1) of the virtual objects' projected bounds
  vec4 tolerance; // x relative change of L_rv / L_r below which a tile is not shaded
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  pc = pc_block;  // MRGI_UNIFORM_COPIES
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
  bool differs = false, all_real = true;
  float d_max = 0.0f, i_max = 0.0f, lo = 3.0e38f, hi = 0.0f;
  for (int y = c0.y; y <= c1.y; ++y) {
    for (int x = c0.x; x <= c1.x; ++x) {
      // Only what the rule reads, straight from the packed bits (upsampled.glsl's layout): R_d
      // and R'_d, R'_i, the kind bits (unpacking every field: 2.2 ms instead of 1.3 on desk_spot).
      uvec4 p = imageLoad(upsampled, ivec2(x, y));
      bool ri_differs = (p.y & 0xffffu) != (p.z >> 16) || (p.y >> 16) != (p.w & 0xffffu) ||
                        (p.z & 0xffffu) != (p.w >> 16);
      differs = differs || ri_differs || (p.x & 0x7fffu) != ((p.x >> 16) & 0x7fffu);
      needed = needed || (p.x & 0x00008000u) != 0u;      // a virtual cell
      all_real = all_real && (p.x & 0x80000000u) != 0u;  // a surface (virtual ones are needed)
      vec2 d = unpackHalf2x16(p.x & 0x7fff7fffu);
      vec2 w = unpackHalf2x16(p.w);
      float riv_max = max(max(unpackHalf2x16(p.z).y, w.x), w.y);
      d_max = max(d_max, abs(d.y - d.x));
      i_max = max(i_max, ri_differs ? riv_max : 0.0f);
      lo = min(lo, d.x);
      hi = max(hi, d.x);
    }
  }
  needed = needed || (differs && !(all_real && ssrt_tile_invisible(d_max, i_max, lo, hi, pc.tolerance.x)));
  if (needed) list[atomicAdd(args[0], 1u)] = uint(id);
}
