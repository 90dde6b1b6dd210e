// Compose's tile classification state (compose/tile_classify.comp, compose/tile_split.comp,
// runtime/src/compose/compose.h): words 0..3 are the VkDispatchIndirectCommand of the tiles a
// virtual surface can reach (x counted by tile_split.comp, y = z = 1, a pad), words 4..7 that of
// the tiles only real surfaces reach, then one flag per output 8 x 8 tile. The list buffer holds
// the first kind's tile indices from entry 0 and the second's from entry tile_count (the output's
// tile count), each in no order.
#ifndef MRGI_COMPOSE_TILE_LISTS_GLSL
#define MRGI_COMPOSE_TILE_LISTS_GLSL

#define MRGI_TILE_ARGS_VIRTUAL 0
#define MRGI_TILE_ARGS_REAL 4
#define MRGI_TILE_FLAGS 8
#define MRGI_TILE_LISTED 1u
#define MRGI_TILE_VIRTUAL_REACH 2u

#endif
