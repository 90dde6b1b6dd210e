#version 460
// ssrt occluder G-buffer: what the transfer's samples read where they land, gathered once per
// texel of the geometry grid (the resolution of the filtered real G-buffer, `geometry_step`
// internal pixels per texel side) into two images:
//   occ_position RGBA32F  xyz the virtual surface (world), w 1 where a virtual object covers it
//   occ_attrs    RGBA32UI x real albedo (the camera colour, upload_gather.glsl camera_at: unorm8
//                rgb + measured), y virtual albedo
//                (unorm8 rgb), z-w virtual normal (3 halves)
// Texel g point-samples internal pixel g s + s/2 of the full-resolution buffers. Why: each
// transfer sample read the virtual position, normal and albedo and the real albedo at its own
// internal pixel, gathers spread over ~10 MB of full-resolution images; on lavapipe the cache
// misses cost more than the reads themselves (desk_spot fast: transfer 23.5 -> 17.5 ms with the
// same reads confined to a 160x120 corner, frame 82 -> 68 ms). The fast levels already read the
// real geometry at this resolution (through the texel's tangent plane, tangent_plane_depth); the
// virtual surface is refined the same way in transfer.comp. At geometry step 1 the copy is exact
// (albedos rounded to 8 bits: below 0.2 % of a sender's reflected light).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };  // internal
layout(std430, set = 0, binding = 1) readonly buffer ColorWords { uint color_words[]; };  // RGB8
layout(std430, set = 0, binding = 2) readonly buffer DepthWords { uint depth_words[]; };  // u16
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 6, rgba32f) writeonly uniform image2D occ_position;
layout(set = 0, binding = 7, rgba32ui) writeonly uniform uimage2D occ_attrs;
// x geometry step s; y, z the internal extent (pixels); w unused.
layout(push_constant) uniform Push { ivec4 step; } pc;

void main() {
  ivec2 g = ivec2(gl_GlobalInvocationID.xy);
  int s = pc.step.x;
  ivec2 size = pc.step.yz;
  ivec2 grid = (size + s - 1) / s;
  if (any(greaterThanEqual(g, grid))) return;
  ivec2 p = min(g * s + ivec2(s / 2), size - 1);
  vec4 ra = camera_at(vec2(p));
  vec4 vp = imageLoad(virtual_position, p);
  vec3 vn = imageLoad(virtual_normal, p).xyz;
  vec3 va = imageLoad(virtual_albedo, p).rgb;
  bool covered = vp.w > 0.5f;
  imageStore(occ_position, g, covered ? vec4(vp.xyz, 1.0f) : vec4(0.0f));
  uvec4 attrs = uvec4(packUnorm4x8(vec4(clamp(ra.rgb, 0.0f, 1.0f), ra.a > 0.5f ? 1.0f : 0.0f)),
                      packUnorm4x8(vec4(clamp(va, 0.0f, 1.0f), 0.0f)),
                      packHalf2x16(vn.xy), packHalf2x16(vec2(vn.z, 0.0f)));
  imageStore(occ_attrs, g, covered ? attrs : uvec4(attrs.x, 0u, 0u, 0u));
}
