#version 460
// ssrt shading into the two solutions the runtime's compose turns into the frame (technique.h):
//   real pixel     L_r  = A R_d,  L_rv = A R'_d + A I_i / pi   (I_i: eq. 14, R'_i where it
//                  differs from R_i), A = the camera colour (recon), R_d = T . l (Sec. 5.4)
//   virtual pixel  L_rv = A_v (R'_d + R'_i / pi), L_r = the real surface behind it
// The compose multiplies the camera image by the ratio of the two (mrgi_shared.h
// differential_compose), which is eq. 13's "multiply the buffers with the colour of I_c" without
// eq. 13's tone mapper: the runtime's compose is shared by all techniques and works in linear
// radiance; eq. 13 itself (ssrt_direct_differential) is kept in transfer_math.h and tested.
// At step 1 the coarse cells are the pixels; above it the Gauss-filtered cells (`upsampled`,
// upsampled.glsl) are read with Catmull-Rom bicubic interpolation (paper OursFast), clamped at 0
// (bicubic overshoots).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"
#include "common/frame_constants.glsl"
#include "shared/transfer_math.h"
#include "ssrt/upsampled.glsl"

// 8 x 8 invocations, one per pixel; the tiled pipeline sets 8 x 1, one per 4 x 2 pixels of its
// 8 x 8 tile (shade_group; as 2 x 4 it ran at twice the time: lavapipe fills its SIMD lanes
// along x only, so a workgroup 2 wide used 2 of 8 lanes).
layout(local_size_x_id = 2, local_size_y_id = 3) in;
// Pipelines from this file (a path a pipeline never takes is compiled out, not branched around:
// lavapipe runs all of a shader's code): kPassThrough writes the camera colour as both solutions
// (skipped transfer, and the first of the two fast-level passes); kTiled shades the 8 x 8 tiles
// ssrt_shade_tiles listed (workgroup i = tiles.list[i]); neither: every pixel.
layout(constant_id = 0) const bool kPassThrough = false;
layout(constant_id = 1) const bool kTiled = false;
// kCompose (with kTiled, solutions at the camera's size): each shaded pixel is composed here
// (mrgi_shared.h compose_encoded, the runtime's compose formula) and written to the runtime's
// output and mask instead of lit_r / lit_rv (Technique::ComposeTiles::composed): the compose
// pass would otherwise read both solutions, the coverage and the camera again per pixel.
layout(constant_id = 4) const bool kCompose = false;
// kEmission: some virtual material emits (virtual_emission holds it; ssrt_init.cpp says why a
// constant).
layout(constant_id = 5) const bool kEmission = false;
// Storage images read with imageLoad: on lavapipe a sampled texelFetch costs 2-3x as much.
layout(set = 0, binding = 0, rgba32f) readonly uniform image2DArray coarse;
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
// The camera frame as uploaded: A = upload_gather.glsl camera_at (what recon's real_albedo
// holds, read only at the pixels shaded).
layout(set = 0, binding = 2, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 9, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
layout(std140, set = 0, binding = 10) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
#include "common/upload_gather.glsl"
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 5, rgba16f) writeonly uniform image2D lit_rv;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D lit_r;
layout(set = 0, binding = 7, rgba32ui) readonly uniform uimage2D upsampled;
layout(std430, set = 0, binding = 8) readonly buffer Tiles { uint list[]; } tiles;
// kCompose: RGBA8 words, the virtual mask in alpha (mrgi_shared.h pack_output_word).
layout(std430, set = 0, binding = 11) writeonly buffer Output { uint out_rgba8[]; };
layout(set = 0, binding = 13, rgba16f) readonly uniform image2D virtual_emission;  // rgb radiance
struct PushConstants {
  ivec4 grid;   // x, y cells; z step in pixels; w unused
  ivec4 size;   // xy used extent of the solutions (internal resolution), z geometry step
                // (internal pixels per texel of real_position)
  ivec4 influence;  // pixels [x0, x1) x [y0, y1) the virtual objects' influence region covers
  vec4 opts;    // x relative tolerance of eq. 14; kCompose: y eps, z alpha_max of the
                // composite (compose_encoded)
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;

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
  vec4 wx = ssrt_catmull_rom(f.x), wy = ssrt_catmull_rom(f.y);
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

// Cell c's centre is pixel c * step + step / 2.
vec2 cell_position(ivec2 pixel) {
  int step = pc.grid.z;
  return (vec2(pixel) - vec2(float(step / 2))) / float(step);
}

// What a pixel needs besides the interpolated shading.
struct PixelInputs {
  bool real_ok, virt, inside;
  vec3 a;
  vec3 camera;  // kCompose: the camera's linear value at the pixel (compose's CI)
};

PixelInputs pixel_inputs(ivec2 pixel) {
  PixelInputs p;
  p.real_ok = imageLoad(real_position, div_nonneg(pixel, pc.size.z)).w > 0.0f;
  p.virt = imageLoad(virtual_position, pixel).w > 0.5f;
  if (kCompose) {
    // At the camera's size (kCompose's condition, with internal_k = color_k) the camera pixel
    // of this pixel is the pixel itself: camera_at's nearest-pixel mapping returns it (a
    // projection round trip is within an ulp of the integer), so its albedo, camera_at's
    // camera_to_radiance clamped, comes from the one decode compose needs as well (three
    // pow() per pixel fewer).
    vec3 decoded = srgb_decode(vec3(color_rgb8(uint(pixel.y * frame.color_depth_size.x + pixel.x))) / 255.0f);
    p.camera = decoded;
    p.a = clamp(decoded / (frame.camera.y > 0.0f ? frame.camera.y : 1.0f), vec3(0.0f), vec3(1.0f));
  } else {
    p.a = camera_at(vec2(pixel)).rgb;
    p.camera = vec3(0.0f);
  }
  p.inside = pixel.x >= pc.influence.x && pixel.x < pc.influence.z &&
             pixel.y >= pc.influence.y && pixel.y < pc.influence.w;
  return p;
}

// The pixel's two solutions, or under kCompose its composite (what compose.comp writes).
void store_solutions(ivec2 pixel, PixelInputs p, vec3 l_r, vec3 l_rv) {
  if (kCompose) {
    uint index = uint(pixel.y * frame.internal_output_size.z + pixel.x);
    vec3 encoded = compose_encoded(p.camera, finite3(l_r), finite3(l_rv), p.virt ? 1.0f : 0.0f,
                                   frame.camera.y, pc.opts.y, pc.opts.z);
    out_rgba8[index] = pack_output_word(encoded, p.virt);
    return;
  }
  imageStore(lit_r, pixel, vec4(l_r, 1.0f));
  imageStore(lit_rv, pixel, vec4(l_rv, 1.0f));
}

// Skipped transfer, or a pixel outside the influence region: nothing virtual changes it, so
// L_rv = L_r and the compose returns the camera colour whatever their common value.
void store_pass_through(ivec2 pixel, PixelInputs p) {
  vec3 v = p.real_ok ? p.a : vec3(0.0f);
  store_solutions(pixel, p, v, v);
}

void store_shaded(ivec2 pixel, PixelInputs p, vec4 s4, vec4 s5, vec4 s6) {
  bool real_ok = p.real_ok, virt = p.virt;
  vec3 a = p.a;
  float rd = s4.x, rd_v = s4.y;
  vec3 ri = s5.xyz, ri_v = s6.xyz;
  vec3 l_r = real_ok ? a * rd : vec3(0.0f);
  vec3 l_rv;
  if (virt) {
    vec3 av = imageLoad(virtual_albedo, pixel).rgb;
    // Plus the surface's own emission (glTF emissive), seen directly. It lights no other
    // surface: the bounce term's senders are lit by the dominant light only (transfer_math.h).
    vec3 emission = kEmission ? imageLoad(virtual_emission, pixel).rgb : vec3(0.0f);
    l_rv = av * (rd_v + ri_v / MRGI_PI) + emission;
  } else {
    l_rv = real_ok ? a * rd_v + a * ssrt_indirect_select(ri, ri_v, pc.opts.x) / MRGI_PI : vec3(0.0f);
  }
  store_solutions(pixel, p, l_r, l_rv);
}

// One pixel on its own (untiled pipelines, and tiled ones at steps other than 4).
void shade_pixel(ivec2 pixel) {
  if (pixel.x >= pc.size.x || pixel.y >= pc.size.y) return;
  PixelInputs p = pixel_inputs(pixel);
  if (kPassThrough || (!p.inside && !p.virt)) {
    store_pass_through(pixel, p);
    return;
  }
  vec4 s4, s5, s6;
  if (pc.grid.z <= 1) {
    ivec2 q = min(pixel, pc.grid.xy - ivec2(1));
    s4 = imageLoad(coarse, ivec3(q, 4));
    s5 = imageLoad(coarse, ivec3(q, 5));
    s6 = imageLoad(coarse, ivec3(q, 6));
  } else {
    sample_bicubic(cell_position(pixel), p.virt ? 2.0f : 1.0f, s4, s5, s6);
  }
  store_shaded(pixel, p, s4, s5, s6);
}

// A tiled invocation at step 4: the 4 x 2 pixels from `origin` (x a multiple of 4, y of 2).
// Their bicubic windows (4 x 4 cells each) all lie in 5 columns x 4 rows of cells, so those 20
// cells are fetched and unpacked once into registers and every pixel sums its own window from
// them: 20 fetches for 8 pixels instead of 128. The per-pixel sums are sample_bicubic's, term
// for term in the same order, so the result is bit-identical. Why: on lavapipe every fetch is a
// per-lane gather; desk_spot fast: 8.5 -> 6.3 ms (of which the camera colour's gather, 4 loads
// and the sRGB decode per pixel, is 1.5).
//   x: pixel origin.x + i has cell position k - 1/2 + i/4 (origin.x = 4k): base column k - 1
//      for i < 2, k for i >= 2, fractions 1/2, 3/4, 0, 1/4;
//   y: origin.y = 4k + o (o = 0 or 2), rows origin.y and +1 share base row k - 1 (o = 0) or k.
void shade_group(ivec2 origin) {
  int k_x = origin.x / 4;
  int base_y = int(floor(cell_position(origin).y));
  float f_y0 = cell_position(origin).y - float(base_y);
  float c_rd[20], c_rdv[20], c_kind[20];
  vec3 c_ri[20], c_riv[20];
  [[unroll]] for (int j = 0; j < 4; ++j) {
    [[unroll]] for (int i = 0; i < 5; ++i) {
      ivec2 q = clamp(ivec2(k_x - 2 + i, base_y - 1 + j), ivec2(0), pc.grid.xy - ivec2(1));
      ssrt_unpack_upsampled(imageLoad(upsampled, q), c_rd[j * 5 + i], c_rdv[j * 5 + i],
                            c_ri[j * 5 + i], c_riv[j * 5 + i], c_kind[j * 5 + i]);
    }
  }
  [[unroll]] for (int py = 0; py < 2; ++py) {
    [[unroll]] for (int px = 0; px < 4; ++px) {
      ivec2 pixel = origin + ivec2(px, py);
      PixelInputs p = pixel_inputs(pixel);
      float kind = p.virt ? 2.0f : 1.0f;
      const int col0 = px < 2 ? 0 : 1;  // first of the 5 columns in this pixel's window
      const float f_x = px == 0 ? 0.5f : (px == 1 ? 0.75f : (px == 2 ? 0.0f : 0.25f));
      float f_y = f_y0 + 0.25f * float(py);
      vec4 wx = ssrt_catmull_rom(f_x), wy = ssrt_catmull_rom(f_y);
      // sample_bicubic's two sums (same kind, any surface) differ only in which cells count,
      // and only one of them is used: the weights decide which first (scalars), then one
      // weighted sum runs over the taps with the other cells' weight 0. Adding 0 * value leaves
      // a sum as it is, so the result is sample_bicubic's, term for term, with half the vector
      // arithmetic (and only the components store_shaded reads: R_d, R'_d, R_i, R'_i).
      float w16[16];
      bool present16[16], same16[16];
      float kw = 0.0f, aw = 0.0f;
      [[unroll]] for (int j = 0; j < 4; ++j) {
        [[unroll]] for (int i = 0; i < 4; ++i) {
          int c = j * 5 + col0 + i;
          float kind_q = c_kind[c];
          bool present = kind_q > 0.5f;
          bool same = present && abs(kind_q - kind) <= 0.5f;
          float w = wx[i] * wy[j];
          w16[j * 4 + i] = w;
          present16[j * 4 + i] = present;
          same16[j * 4 + i] = same;
          aw += present ? w : 0.0f;
          kw += same ? w : 0.0f;
        }
      }
      bool use_same = abs(kw) > 1e-4f;
      float wsum = use_same ? kw : aw;
      vec2 sd = vec2(0.0f);
      vec3 si = vec3(0.0f), siv = vec3(0.0f);
      [[unroll]] for (int j = 0; j < 4; ++j) {
        [[unroll]] for (int i = 0; i < 4; ++i) {
          int c = j * 5 + col0 + i;
          bool counts = use_same ? same16[j * 4 + i] : present16[j * 4 + i];
          float w = counts ? w16[j * 4 + i] : 0.0f;
          sd += w * vec2(c_rd[c], c_rdv[c]);
          si += w * c_ri[c];
          siv += w * c_riv[c];
        }
      }
      vec4 s4 = vec4(0.0f), s5 = vec4(0.0f), s6 = vec4(0.0f);
      if (abs(wsum) > 1e-4f) {
        s4 = vec4(max(sd / wsum, vec2(0.0f)), 0.0f, 0.0f);
        s5 = vec4(max(si / wsum, vec3(0.0f)), 0.0f);
        s6 = vec4(max(siv / wsum, vec3(0.0f)), 0.0f);
      }
      if (pixel.x < pc.size.x && pixel.y < pc.size.y) {
        if (!p.inside && !p.virt) {
          store_pass_through(pixel, p);
        } else {
          store_shaded(pixel, p, s4, s5, s6);
        }
      }
    }
  }
}

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  if (kTiled) {
    uint t = tiles.list[spread_workgroup_index_1d()];
    int tiles_x = (pc.size.x + 7) / 8;
    ivec2 tile = ivec2(int(t) % tiles_x, int(t) / tiles_x) * 8;
    // local_size 8 x 1: lavapipe packs invocations into SIMD lanes along x only.
    int i = int(gl_LocalInvocationID.x);
    ivec2 origin = tile + ivec2(i & 1, i >> 1) * ivec2(4, 2);
    if (pc.grid.z == 4) {
      shade_group(origin);
    } else {
      for (int py = 0; py < 2; ++py)
        for (int px = 0; px < 4; ++px) shade_pixel(origin + ivec2(px, py));
    }
    return;
  }
  shade_pixel(spread_invocation_id());
}
