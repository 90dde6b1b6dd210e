#version 460
// The flags tile_classify.comp set, as compose's two tile lists (compose/tile_lists.glsl): one
// invocation per output 8 x 8 tile; a listed tile goes to the list of tiles a virtual surface
// can reach or to that of real-only tiles, and its list's dispatch count grows by one. Kept apart
// from the classifier because a tile's kind is known only once every texel has flagged it.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "compose/tile_lists.glsl"

layout(local_size_x = 64) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
layout(std430, set = 0, binding = 1) buffer TileState { uint words[]; };
layout(std430, set = 0, binding = 2) writeonly buffer TileList { uint list[]; };

void main() {
  ivec2 out_size = frame_ubo.internal_output_size.zw;
  uint tile_count = uint(((out_size.x + 7) / 8) * ((out_size.y + 7) / 8));
  uint tile = gl_GlobalInvocationID.x;
  if (tile >= tile_count) return;
  uint flag = words[MRGI_TILE_FLAGS + tile];
  if ((flag & MRGI_TILE_LISTED) == 0u) return;
  if ((flag & MRGI_TILE_VIRTUAL_REACH) != 0u)
    list[atomicAdd(words[MRGI_TILE_ARGS_VIRTUAL], 1u)] = tile;
  else
    list[tile_count + atomicAdd(words[MRGI_TILE_ARGS_REAL], 1u)] = tile;
}
