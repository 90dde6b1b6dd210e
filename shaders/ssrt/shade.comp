#version 460
// ssrt shading into the two solutions the runtime's compose turns into the frame (technique.h):
//   real pixel     L_r  = A R_d,  L_rv = A R'_d + A I_i / pi   (I_i: eq. 14, R'_i where it
//                  differs from R_i), A = the camera colour (recon), R_d = T . l (Sec. 5.4)
//   virtual pixel  L_rv = A_v (R'_d + R'_i / pi), L_r = the real surface behind it
// The compose multiplies the camera image by the ratio of the two (mrgi_shared.h
// differential_compose), which is eq. 13's "multiply the buffers with the colour of I_c" without
// eq. 13's tone mapper: the runtime's compose is shared by all techniques and works in linear
// radiance; eq. 13 itself (ssrt_direct_differential) is kept in ssrt_math.h and tested.
// At step 1 the coarse cells are the pixels; above it the Gauss-filtered cells (`upsampled`,
// upsampled.glsl) are read with Catmull-Rom bicubic interpolation (paper OursFast), clamped at 0
// (bicubic overshoots).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "ssrt/ssrt_math.h"
#include "ssrt/upsampled.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// Pipelines from this file (a path a pipeline never takes is compiled out, not branched around:
// lavapipe runs all of a shader's code): kPassThrough writes the camera colour as both solutions
// (skipped transfer, and the first of the two fast-level passes); kTiled shades the 8 x 8 tiles
// ssrt_shade_tiles listed (workgroup i = tiles.list[i]); neither: every pixel.
layout(constant_id = 0) const bool kPassThrough = false;
layout(constant_id = 1) const bool kTiled = false;
// Storage images read with imageLoad: on lavapipe a sampled texelFetch costs 2-3x as much.
layout(set = 0, binding = 0, rgba32f) readonly uniform image2DArray coarse;
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
// The camera frame as uploaded: A = upload_gather.glsl camera_at (what recon's real_albedo
// holds, read only at the pixels shaded).
layout(std430, set = 0, binding = 2) readonly buffer ColorWords { uint color_words[]; };  // RGB8
layout(std430, set = 0, binding = 9) readonly buffer DepthWords { uint depth_words[]; };  // u16
layout(std140, set = 0, binding = 10) uniform FrameUbo { FrameConstants frame; };
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 5, rgba16f) writeonly uniform image2D lit_rv;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D lit_r;
layout(set = 0, binding = 7, rgba32ui) readonly uniform uimage2D upsampled;
layout(std430, set = 0, binding = 8) readonly buffer Tiles { uint list[]; } tiles;
layout(push_constant) uniform Push {
  ivec4 grid;   // x, y cells; z step in pixels; w unused
  ivec4 size;   // xy used extent of the solutions (internal resolution), z geometry step
                // (internal pixels per texel of real_position)
  ivec4 influence;  // pixels [x0, x1) x [y0, y1) the virtual objects' influence region covers
  vec4 opts;    // x relative tolerance of eq. 14
} pc;

vec4 cubic_weights(float t) {
  // Catmull-Rom.
  float t2 = t * t, t3 = t2 * t;
  return vec4(-0.5f * t3 + t2 - 0.5f * t, 1.5f * t3 - 2.5f * t2 + 1.0f,
              -1.5f * t3 + 2.0f * t2 + 0.5f * t, 0.5f * t3 - 0.5f * t2);
}

// Bicubic over the cells that see the same kind of surface as the pixel (1 real, 2 virtual),
// renormalised by the weights of the cells used; where the 4x4 neighbourhood holds no cell of
// the pixel's kind (thin virtual parts at 4x4), over the cells of any surface.
// Both sums are accumulated in one pass over the 16 cells: as two calls (same kind, then any
// kind where the first found nothing) lavapipe ran the second for every pixel, since a
// divergent `if` runs under a lane mask, which doubled this pass's fetches. Each sum
// takes the same terms in the same order as one call would, so the result is unchanged.
void sample_bicubic(vec2 c, float kind, out vec4 s4, out vec4 s5, out vec4 s6) {
  vec2 base = floor(c);
  vec2 f = c - base;
  vec4 wx = cubic_weights(f.x), wy = cubic_weights(f.y);
  vec4 k4 = vec4(0.0f), k5 = vec4(0.0f), k6 = vec4(0.0f);  // same kind
  vec4 a4 = vec4(0.0f), a5 = vec4(0.0f), a6 = vec4(0.0f);  // any surface
  float kw = 0.0f, aw = 0.0f;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      ivec2 q = clamp(ivec2(base) + ivec2(i - 1, j - 1), ivec2(0), pc.grid.xy - ivec2(1));
      float rd, rd_v, kind_q;
      vec3 ri, ri_v;
      ssrt_unpack_upsampled(imageLoad(upsampled, q), rd, rd_v, ri, ri_v, kind_q);
      if (kind_q < 0.5f) continue;
      float w = wx[i] * wy[j];
      vec4 a = vec4(rd, rd_v, 0.0f, kind_q);
      vec4 t5 = vec4(ri, 1.0f);
      vec4 t6 = vec4(ri_v, 1.0f);
      a4 += w * a;
      a5 += w * t5;
      a6 += w * t6;
      aw += w;
      if (abs(a.w - kind) > 0.5f) continue;
      k4 += w * a;
      k5 += w * t5;
      k6 += w * t6;
      kw += w;
    }
  }
  bool same = abs(kw) > 1e-4f;
  float wsum = same ? kw : aw;
  if (abs(wsum) > 1e-4f) {
    s4 = max((same ? k4 : a4) / wsum, vec4(0.0f));
    s5 = max((same ? k5 : a5) / wsum, vec4(0.0f));
    s6 = max((same ? k6 : a6) / wsum, vec4(0.0f));
    return;
  }
  s4 = vec4(0.0f); s5 = vec4(0.0f); s6 = vec4(0.0f);
}

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (kTiled) {
    uint t = tiles.list[gl_WorkGroupID.x];
    int tiles_x = (pc.size.x + 7) / 8;
    pixel = ivec2(int(t) % tiles_x, int(t) / tiles_x) * 8 + ivec2(gl_LocalInvocationID.xy);
  }
  ivec2 used = pc.size.xy;
  if (pixel.x >= used.x || pixel.y >= used.y) return;
  bool real_ok = imageLoad(real_position, pixel / pc.size.z).w > 0.0f;
  bool virt = imageLoad(virtual_position, pixel).w > 0.5f;
  vec3 a = camera_at(vec2(pixel)).rgb;
  bool inside = pixel.x >= pc.influence.x && pixel.x < pc.influence.z &&
                pixel.y >= pc.influence.y && pixel.y < pc.influence.w;
  if (kPassThrough || (!inside && !virt)) {
    // Skipped transfer, or a pixel outside the influence region: nothing virtual changes it,
    // so L_rv = L_r and the compose returns the camera colour whatever their common value.
    vec4 v = vec4(real_ok ? a : vec3(0.0f), 1.0f);
    imageStore(lit_r, pixel, v);
    imageStore(lit_rv, pixel, v);
    return;
  }
  vec4 s4, s5, s6;
  int step = pc.grid.z;
  if (step <= 1) {
    ivec2 q = min(pixel, pc.grid.xy - ivec2(1));
    s4 = imageLoad(coarse, ivec3(q, 4));
    s5 = imageLoad(coarse, ivec3(q, 5));
    s6 = imageLoad(coarse, ivec3(q, 6));
  } else {
    // Cell c's centre is pixel c * step + step / 2.
    vec2 c = (vec2(pixel) - vec2(float(step / 2))) / float(step);
    sample_bicubic(c, virt ? 2.0f : 1.0f, s4, s5, s6);
  }
  float rd = s4.x, rd_v = s4.y;
  vec3 ri = s5.xyz, ri_v = s6.xyz;
  vec3 l_r = real_ok ? a * rd : vec3(0.0f);
  vec3 l_rv;
  if (virt) {
    vec3 av = imageLoad(virtual_albedo, pixel).rgb;
    l_rv = av * (rd_v + ri_v / MRGI_PI);
  } else {
    l_rv = real_ok ? a * rd_v + a * ssrt_indirect_select(ri, ri_v, pc.opts.x) / MRGI_PI : vec3(0.0f);
  }
  imageStore(lit_r, pixel, vec4(l_r, 1.0f));
  imageStore(lit_rv, pixel, vec4(l_rv, 1.0f));
}
