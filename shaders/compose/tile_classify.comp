#version 460
// Compose's own tile list, for techniques that list none (Technique::compose_tiles): the 8 x 8
// output tiles whose composite can differ visibly from the camera frame. One invocation per
// solution texel (internal resolution, used extent); a texel that is virtual (or holds the centre
// of an output pixel the output-resolution coverage marks virtual), or whose two
// solutions differ by more than compose_tile_invisible allows, marks every output tile whose
// pixels read it (compose.comp: the bilinear taps floor(ipos), floor(ipos) + 1 with
// ipos = (p + 0.5) * used / out - 0.5) by its flag; tile_split.comp then lists the flagged
// tiles. Outside the listed tiles compose writes the camera frame (on the host when the output
// has the camera's size), so a technique whose solutions are equal away from the virtual
// objects' influence (baseline, dlpv) pays for the composite only where it shows. On lavapipe a shader runs all of its code for every invocation: pixels that
// need no composite can only be saved by not dispatching them.
// Each tile's flag says whether it is listed (bit 0) and whether a virtual texel, or an output
// pixel the coverage marks, is within its pixels' reach (bit 1): compose runs the tiles without
// it through a variant that reads neither the mask nor the coverage (compose.comp kRealTiles).
// compose_tiles_reset zeroed every flag first; tile_split.comp turns the flags into the lists.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "compose/tile_lists.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D lit_rv;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D lit_r;
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;  // w: coverage
// words 0..7: the two lists' VkDispatchIndirectCommands (tile_split.comp); then one flag per
// output tile (MRGI_TILE_LISTED, MRGI_TILE_VIRTUAL_REACH).
layout(std430, set = 0, binding = 4) coherent buffer TileState { uint words[]; };
// The coverage at the output resolution where the solutions are smaller (compose.comp's mask
// there): an object thinner than a texel covers output pixels no texel centre of it falls in.
layout(set = 0, binding = 6, r32f) readonly uniform image2D virtual_coverage;
struct ClassifyConstants {
  vec4 compose;  // x eps, y alpha_max (ComposeSettings), z tolerance (8-bit levels)
  // The output pixels the coverage raster drew this frame (x0, y0, x1, y1: [x0, x1) x [y0, y1),
  // VirtualGBuffer::output_coverage_area): outside it no pixel is covered, so texels there skip
  // the footprint test. Empty at the output's own size.
  ivec4 coverage_area;
};
layout(push_constant) uniform Classify { ClassifyConstants classify_block; };
ClassifyConstants classify;

void mark(int tile, uint bits) {
  if ((words[MRGI_TILE_FLAGS + tile] & bits) == bits) return;  // (a plain read first: most marks find it set)
  atomicOr(words[MRGI_TILE_FLAGS + tile], bits);
}

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  classify = classify_block;
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 used = frame.internal_output_size.xy;
  ivec2 out_size = frame.internal_output_size.zw;
  if (any(greaterThanEqual(texel, used))) return;
  bool shows = imageLoad(virtual_position, texel).w > 0.5f;
  vec2 s = vec2(out_size) / vec2(used);
  if (!shows && used != out_size) {
    // The output pixels whose centre falls in this texel: (p + 0.5) / s in [texel, texel + 1),
    // within the area the coverage raster drew.
    ivec2 q0 = max(ivec2(ceil(vec2(texel) * s - 0.5f)), classify.coverage_area.xy);
    ivec2 q1 = min(ivec2(ceil(vec2(texel + 1) * s - 0.5f)), classify.coverage_area.zw);
    for (int y = q0.y; y < q1.y && !shows; ++y)
      for (int x = q0.x; x < q1.x; ++x) shows = shows || imageLoad(virtual_coverage, ivec2(x, y)).r > 0.5f;
  }
  const uint bits = shows ? MRGI_TILE_LISTED | MRGI_TILE_VIRTUAL_REACH : MRGI_TILE_LISTED;
  if (!shows) {
    float exposure = frame.camera.y;
    vec3 rv = clamp(finite3(imageLoad(lit_rv, texel).rgb) * exposure, vec3(0.0f), vec3(1.0f));
    vec3 r = clamp(finite3(imageLoad(lit_r, texel).rgb) * exposure, vec3(0.0f), vec3(1.0f));
    shows = !compose_tile_invisible(r, rv, classify.compose.x, classify.compose.y, classify.compose.z);
  }
  if (!shows) return;
  // Output pixels reading this texel: bilinear taps at floor(ipos) = texel - 1 or texel, i.e.
  // (p + 0.5) * used / out in [texel - 0.5, texel + 1.5), and the nearest texel; widened by a
  // pixel each way so rounding never loses one. At the output's own size only p = texel.
  ivec2 p0 = texel, p1 = texel;
  if (used != out_size) {
    p0 = max(ivec2(floor((vec2(texel) - 0.5f) * s - 0.5f)) - 1, ivec2(0));
    p1 = min(ivec2(ceil((vec2(texel) + 1.5f) * s - 0.5f)) + 1, out_size - 1);
  }
  int tiles_x = (out_size.x + 7) / 8;
  for (int ty = p0.y / 8; ty <= p1.y / 8; ++ty)
    for (int tx = p0.x / 8; tx <= p1.x / 8; ++tx) mark(ty * tiles_x + tx, bits);
}
