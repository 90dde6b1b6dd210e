#version 460
// dir: temporal smoothing of the merged VPL light against VPL flicker (the DIR paper's [4],
// Knecht et al. 2010: each pixel blends the previous frame's illumination by a confidence from
// the change of normal, position and illumination). The pixel's surface point is reprojected
// into the previous frame (its pose, the same intrinsics) and the previous smoothed light is read
// there with bilinear weights, each tap kept only where it shows the same surface: its normal
// and its camera distance (from the previous camera) within indirect_pack.glsl's same_surface
// tolerances; the kept weight is the position and normal confidence. The illumination confidence
// falls from 1 to 0 as the relative change of the light's luminance grows from `params.w` to
// twice that: flicker of a few VPLs moves a merged pixel by tens of percent, a lamp or an object
// that moved by more. Output = mix(current, history, blend x confidence), packed with the
// current key; it is the next frame's history. The current light is the merge's: this pass
// runs its column half (dir/merge_column.glsl) on the row-merged image itself.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "gi/indirect_pack.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 3, rgba32ui) readonly uniform uimage2D rows;  // merge_rows.comp's
layout(set = 0, binding = 4, rgba32ui) readonly uniform uimage2D history;
layout(set = 0, binding = 5, rgba32ui) writeonly uniform uimage2D smoothed;
layout(push_constant) uniform Params {
  mat4 previous_world_to_camera;  // the previous frame's pose, inverted
  vec4 previous_camera;           // xyz its camera centre (world); w: 1 = history valid
  ivec4 extent;                   // x, y: the indirect images' used size; z: G-buffer pixels a
                                  // texel; w: the merge's side (DirParams vpls.w)
  vec4 params;                    // x: blend; w: relative luminance change where confidence starts to fall
} params_block;
#include "dir/merge_column.glsl"

void main() {
  frame = frame_ubo;  // MRGI_UNIFORM_COPIES
  mat4 previous_world_to_camera = params_block.previous_world_to_camera;
  vec4 previous_camera = params_block.previous_camera;
  ivec4 extent = params_block.extent;
  vec4 params = params_block.params;
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, extent.xy))) return;
  uvec4 current = merge_column(texel, extent.xy, extent.w);
  if (current.w == 0u || previous_camera.w < 0.5f) {
    imageStore(smoothed, texel, current);
    return;
  }
  ivec2 pixel = min(texel * extent.z, frame.internal_output_size.xy - 1);
  vec4 vpos = imageLoad(virtual_position, pixel);
  bool is_virtual = vpos.w > 0.5f;
  vec3 p = is_virtual ? vpos.xyz : imageLoad(real_position, pixel).xyz;
  vec3 q = (previous_world_to_camera * vec4(p, 1.0f)).xyz;
  if (!(q.z > 1e-3f)) {
    imageStore(smoothed, texel, current);
    return;
  }
  // Where the point was in the previous frame's indirect grid (texel t samples G-buffer pixel
  // t * extent.z), and the key it had there.
  vec2 at = project_pinhole(q, frame.internal_k) / float(extent.z);
  vec3 n = oct_decode(unpackSnorm4x8(current.w).xy);
  uint expected = pack_indirect(vec3(0.0f), vec3(0.0f), n, max(distance(p, previous_camera.xyz), 1e-3f), is_virtual).w;
  ivec2 i0 = ivec2(floor(at));
  vec2 f = at - vec2(i0);
  vec3 hist_rv = vec3(0.0f), hist_r = vec3(0.0f);
  float kept = 0.0f;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 s = i0 + o;
    if (any(lessThan(s, ivec2(0))) || any(greaterThanEqual(s, extent.xy))) continue;
    uvec4 tap = imageLoad(history, s);
    if (!same_surface(expected, tap.w)) continue;
    float w = (o.x == 1 ? f.x : 1.0f - f.x) * (o.y == 1 ? f.y : 1.0f - f.y);
    hist_rv += w * unpack_indirect_rv(tap);
    hist_r += w * unpack_indirect_r(tap);
    kept += w;
  }
  vec3 rv = unpack_indirect_rv(current), r = unpack_indirect_r(current);
  float confidence = 0.0f;
  if (kept > 1e-4f) {
    hist_rv /= kept;
    hist_r /= kept;
    float now = abs(luminance(rv)) + abs(luminance(r)), before = abs(luminance(hist_rv)) + abs(luminance(hist_r));
    float change = abs(now - before) / max(max(now, before), 1e-6f);
    float illumination = clamp(2.0f - change / params.w, 0.0f, 1.0f);
    confidence = clamp(kept, 0.0f, 1.0f) * illumination;
  }
  float b = params.x * confidence;
  rv = mix(rv, hist_rv, b);
  r = mix(r, hist_r, b);
  imageStore(smoothed, texel, pack_indirect(rv, r, vec3(0.0f), 0.0f, false) & uvec4(~0u, ~0u, ~0u, 0u) | uvec4(0u, 0u, 0u, current.w));
}
