#version 460
// Reconstruction step 2: raw depth (u16), 3x3-median filtered, merged with the previous frame's
// warped filtered depth (DIR paper section 4.2; recon/warp_depth.comp) -> view-space ->
// world-space positions, and the real albedo estimate from the camera colour, at the internal
// resolution. The merged depth and its weight are written for the next frame, and the warp
// target is cleared for it. 0 depth = invalid; an invalid pixel is written as all zeros and
// stays invalid in every later step (normals, caster mesh, shading).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "recon/depth_filter.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, rgba32f) writeonly uniform image2D real_position;  // xyz world, w z
layout(set = 0, binding = 4, rgba16f) writeonly uniform image2D real_albedo;    // rgb, a valid
layout(set = 0, binding = 5, r32ui) uniform uimage2D warped;                    // read, cleared
layout(set = 0, binding = 6, rg32f) writeonly uniform image2D filtered_depth;   // z m, weight
// x: 1 when `warped` holds the previous frame, y: weight cap (frames), z/w: same-surface rule
// |z_new - z_warped| <= max(z * z_new, w metres); options.x: 1 = median on the raw depth.
struct PushConstants { vec4 merge; ivec4 options; };
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

// Spatial step before the temporal merge: the median of the valid raw depths in the 3x3
// neighbourhood of a valid pixel. Why: the sample's Kinect-like depth has single-pixel
// outliers and disparity-quantisation steps that a running average only dilutes over many
// frames (and the first frame has no history at all); a median of the centre's own surface
// removes them without blurring or moving depth edges (it returns one of the input depths).
// Holes stay holes.
//
// How: Paeth's 19-exchange median-of-9 network (Graphics Gems, 1990) on nine registers. The k
// neighbours that do not count (outside, a hole, another surface) enter as alternately the
// largest and the smallest uint, ceil(k/2) of the one and floor(k/2) of the other, so the
// network's middle element is the median of the n = 9 - k valid depths, element n / 2 of them
// sorted: exactly what an insertion sort into an array gave, without the per-pixel scratch
// array that cost 28 of recon_positions' 70 ms on lavapipe.
uint median_neighbour(ivec2 q, ivec2 size, uint centre, inout int rejected, inout int valid) {
  uint d = 0u;
  if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size)))
    d = depth_value(uint(q.y * size.x + q.x));
  // Same-surface neighbours only (the normals' depth-edge rule): a median over both sides of an
  // edge would erode convex corners by a pixel and move real shadow outlines.
  if (d == 0u || abs(float(d) - float(centre)) > MRGI_DEPTH_EDGE_RELATIVE * float(min(d, centre))) {
    ++rejected;
    return (rejected & 1) != 0 ? 0xFFFFFFFFu : 0u;
  }
  ++valid;
  return d;
}

void sort2(inout uint a, inout uint b) {
  uint lo = min(a, b);
  b = max(a, b);
  a = lo;
}

uint median_depth(ivec2 c, ivec2 size) {
  uint centre = depth_value(uint(c.y * size.x + c.x));
  if (centre == 0u) return 0u;
  int rejected = 0, valid = 0;
  uint p0 = median_neighbour(c + ivec2(-1, -1), size, centre, rejected, valid);
  uint p1 = median_neighbour(c + ivec2(0, -1), size, centre, rejected, valid);
  uint p2 = median_neighbour(c + ivec2(1, -1), size, centre, rejected, valid);
  uint p3 = median_neighbour(c + ivec2(-1, 0), size, centre, rejected, valid);
  uint p4 = median_neighbour(c, size, centre, rejected, valid);
  uint p5 = median_neighbour(c + ivec2(1, 0), size, centre, rejected, valid);
  uint p6 = median_neighbour(c + ivec2(-1, 1), size, centre, rejected, valid);
  uint p7 = median_neighbour(c + ivec2(0, 1), size, centre, rejected, valid);
  uint p8 = median_neighbour(c + ivec2(1, 1), size, centre, rejected, valid);
  if (valid < 3) return centre;
  sort2(p1, p2); sort2(p4, p5); sort2(p7, p8);
  sort2(p0, p1); sort2(p3, p4); sort2(p6, p7);
  sort2(p1, p2); sort2(p4, p5); sort2(p7, p8);
  sort2(p0, p3); sort2(p5, p8); sort2(p4, p7);
  sort2(p3, p6); sort2(p1, p4); sort2(p2, p5);
  sort2(p4, p7); sort2(p2, p4); sort2(p4, p6);
  sort2(p2, p4);
  return p4;
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 internal_size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, internal_size))) return;
  ivec2 color_size = frame.color_depth_size.xy;
  ivec2 depth_size = frame.color_depth_size.zw;

  // Colour and depth cameras share their centre and orientation (capture.json has intrinsics
  // only), so depth is brought into the colour camera by a per-pixel gather along the same ray:
  // identity when the intrinsics match, else the nearest depth sample (never interpolated,
  // which would invent depths between a foreground and a background surface).
  vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, frame.internal_k);
  ivec2 dp = nearest_pixel(ray, frame.depth_k, depth_size);
  float z_new = 0.0f;
  if (dp.x >= 0) {
    uint raw = pc.options.x != 0 ? median_depth(dp, depth_size)
                                 : depth_value(uint(dp.y * depth_size.x + dp.x));
    z_new = raw == 0u ? 0.0f : float(raw) / frame.camera.x;
  }
  if (!(z_new > 0.0f) || isinf(z_new)) z_new = 0.0f;

  // Merge (KinectFusion-style weighted running average, DIR section 4.2): same surface ->
  // average with the warped history, weight + 1 up to the cap (so the filter becomes an
  // exponential average that still follows slow changes); different surfaces -> the new depth
  // only (no smearing of moved geometry); a hole in the new depth keeps the warped depth with
  // one weight less, so a filled hole fades out after `cap` frames unless seen again.
  vec2 old = vec2(0.0f);
  if (pc.merge.x > 0.5f) old = unpack_warped(imageLoad(warped, pixel).x);
  imageStore(warped, pixel, uvec4(MRGI_WARP_EMPTY));  // ready for the next frame's warp
  float z = z_new, weight = z_new > 0.0f ? 1.0f : 0.0f;
  if (old.x > 0.0f && old.y >= 1.0f) {
    if (z_new > 0.0f) {
      float tolerance = max(pc.merge.z * z_new, pc.merge.w);
      if (abs(z_new - old.x) <= tolerance) {
        z = (old.x * old.y + z_new) / (old.y + 1.0f);
        weight = min(old.y + 1.0f, pc.merge.y);
      }
    } else if (old.y > 1.0f) {
      z = old.x;
      weight = old.y - 1.0f;
    }
  }
  imageStore(filtered_depth, pixel, vec4(z, weight, 0.0f, 0.0f));
  if (!(z > 0.0f)) {
    imageStore(real_position, pixel, vec4(0.0f));
    imageStore(real_albedo, pixel, vec4(0.0f));
    return;
  }
  vec4 world = frame.camera_to_world * vec4(ray * z, 1.0f);
  imageStore(real_position, pixel, vec4(world.xyz, z));

  // Albedo: the camera colour, sRGB-decoded and divided by the exposure, is used as the diffuse
  // reflectance. This is the DIR paper's approximation (section 4.3: "the diffuse intensity is
  // set to the input image color"): it is reflectance times incident light, not reflectance;
  // the differential compose divides the model out again, so the error only affects the delta.
  // Clamped to [0, 1] because a reflectance above 1 would create energy in later bounces.
  vec3 albedo = vec3(0.0f);
  ivec2 cp = nearest_pixel(ray, frame.color_k, color_size);
  if (cp.x >= 0) {
    vec3 encoded = vec3(color_rgb8(uint(cp.y * color_size.x + cp.x))) / 255.0f;
    albedo = clamp(camera_to_radiance(encoded, frame.camera.y), vec3(0.0f), vec3(1.0f));
  }
  imageStore(real_albedo, pixel, vec4(albedo, 1.0f));
}
