#version 460
// ssrt occluder G-buffer: what the transfer's samples read where they land, gathered once per
// texel of the occluder grid (`occluder_step` internal pixels per texel side) into two packed
// images, so a sample reads two texels instead of four (real position and normal, virtual
// surface and albedos):
//   occ_a RGBA32UI  x real camera depth (float bits, 0 = none) of the geometry texel under the
//                   sample pixel, y its world normal (oct_pack), z the camera colour there
//                   (upload_gather.glsl camera_at: unorm8 rgb + measured), w virtual camera depth
//                   (float bits, 0 = no virtual surface)
//   occ_b RG32UI    x virtual world normal (oct_pack), y virtual albedo (unorm8 rgb)
// Texel g point-samples internal pixel p = g s + s/2; the transfer rebuilds the positions from
// the depths (the real one at the centre of p's geometry texel, the virtual one at p), so it
// needs no world-space positions here. Why the gather: each transfer sample read the virtual
// position, normal and albedo and the real albedo at its own internal pixel, gathers spread
// over ~10 MB of full-resolution images; on lavapipe the cache misses cost more than the
// reads (desk_spot fast: transfer 23.5 -> 17.5 ms), and every image read costs per-lane address
// work (two packed reads instead of four). Albedos are rounded to 8 bits (below 0.2 % of a
// sender's reflected light), normals to 16-bit octahedral (below 0.01 degrees).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)  // internal
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 6, rgba32f) readonly uniform image2D real_position;  // geometry grid
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 8, rgba32ui) writeonly uniform uimage2D occ_a;
layout(set = 0, binding = 9, rg32ui) writeonly uniform uimage2D occ_b;
// x occluder step s; y, z the internal extent (pixels); w geometry step.
struct PushConstants { ivec4 step; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 g = spread_invocation_id();
  int s = pc.step.x;
  ivec2 size = pc.step.yz;
  ivec2 grid = div_nonneg(size + s - 1, s);
  if (any(greaterThanEqual(g, grid))) return;
  ivec2 p = min(g * s + ivec2(s / 2), size - 1);
  ivec2 gt = div_nonneg(p, pc.step.w);
  vec4 rp = imageLoad(real_position, gt);
  vec3 rn = imageLoad(real_normal, gt).xyz;
  vec4 ra = camera_at(vec2(p));
  vec4 vp = imageLoad(virtual_position, p);
  vec3 vn = imageLoad(virtual_normal, p).xyz;
  vec3 va = imageLoad(virtual_albedo, p).rgb;
  bool real_ok = rp.w > 0.0f;
  bool covered = vp.w > 0.5f;
  float zv = covered ? (frame.world_to_camera * vec4(vp.xyz, 1.0f)).z : 0.0f;
  uint a_x = real_ok ? floatBitsToUint(rp.w) : 0u;
  uint a_y = real_ok ? oct_pack(normalize(rn + vec3(1e-9f))) : 0u;
  uint a_z = packUnorm4x8(vec4(clamp(ra.rgb, 0.0f, 1.0f), ra.a > 0.5f ? 1.0f : 0.0f));
  uint a_w = covered && zv > 0.0f ? floatBitsToUint(zv) : 0u;
  imageStore(occ_a, g, uvec4(a_x, a_y, a_z, a_w));
  imageStore(occ_b, g, covered ? uvec4(oct_pack(normalize(vn + vec3(1e-9f))),
                                       packUnorm4x8(vec4(clamp(va, 0.0f, 1.0f), 0.0f)), 0u, 0u)
                               : uvec4(0u));
}
