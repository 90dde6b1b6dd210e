#version 460
// Compose (caustics-DIR eq. 1-2) at the output resolution:
//   real pixels:    out = CI + alpha * (TM(L_rv) - TM(L_r)),  alpha = CI / TM(L_r)
//   virtual pixels: out = TM(L_rv)
// TM is the camera model of mrgi_shared.h (radiance * exposure, clipped at 1, then sRGB) and the
// whole composite is done on the linear side of that sRGB curve: the identity
// CI * TM(L_rv) / TM(L_r) scales the light the camera measured, which is only true for values
// proportional to radiance; differences of sRGB-encoded values would darken shadows by the
// curve's slope instead. alpha is guarded by differential_compose (mrgi_shared.h): it blends to
// 1 where TM(L_r) < eps (no modelled light: the delta is added as is) and is clamped to
// [0, alpha_max] (a barely lit model point would otherwise multiply a virtual lamp's light by
// an unbounded factor). NaN or Inf never reach the output: inputs are sanitised first.
//
// Pipelines from this file, chosen per frame by the runtime, specialised on whether the
// camera and output sizes match (kSameSize): kCameraOnly (nothing virtual in view) writes the
// camera frame, a byte copy when the sizes match; the others run the composite (joint_taps up-
// samples the solutions where they are smaller than the output: four taps of each solution and
// of virtual_position, and the coverage), kSameInternal when the solutions are at the output size
// (one texel each and the mask from virtual_position: 3 fetches beside the camera's), each also
// over listed tiles (kTiled) and over tiles no virtual surface reaches (kRealTiles). Not one shader
// with branches: on lavapipe a shader costs about as much as all of its code, taken or not
// (measured at 640x480, x2 threads: the copy alone 0.85 ms as its own pipeline, 8 ms with the
// composite behind a never-entered uniform `if`), so each path is compiled out of the other.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/workgroup_order.glsl"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(constant_id = 0) const bool kSameSize = true;     // camera size == output size
layout(constant_id = 1) const bool kCameraOnly = false;  // output = camera frame
layout(constant_id = 2) const bool kSameInternal = false; // solutions' used size == output size
// kTiled (with kSameInternal): only the 8 x 8 tiles the technique listed (Technique::
// compose_tiles), workgroup i = tiles.list[i]; the camera-only pipeline wrote every pixel first.
layout(constant_id = 3) const bool kTiled = false;
// kRealTiles (with kTiled): tiles no virtual texel or covered output pixel reaches (compose's own
// classification, compose/tile_split.comp): every pixel is real and every tap on its side, so
// neither the mask nor the coverage is read (the same arithmetic as the general path there).
layout(constant_id = 4) const bool kRealTiles = false;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
// Storage images read with imageLoad: on lavapipe a sampled texelFetch costs 2-3x as much.
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D lit_rv;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D lit_r;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D virtual_position;  // w: coverage
// RGBA8 words, the virtual mask in alpha (mrgi_shared.h pack_output_word).
layout(std430, set = 0, binding = 5) writeonly buffer Output { uint out_rgba8[]; };
layout(std430, set = 0, binding = 7) readonly buffer Tiles { uint list[]; } tiles;
// The virtual objects' coverage at the output resolution (recon::VirtualGBuffer::
// output_coverage), read where the solutions are at a lower internal resolution: the mask at the
// output's pixels. (The variants at the output's own size read virtual_position's w instead.)
layout(set = 0, binding = 8, r32f) readonly uniform image2D virtual_coverage;
struct ParamsConstants {
  vec4 compose;      // x eps (linear camera units), y alpha_max
  // The output pixels the coverage raster drew and cleared this frame ([x, z) x [y, w),
  // ComposeInputs::coverage_area): outside it the coverage is 0 whatever the image holds (its
  // earlier contents are not kept by every driver).
  ivec4 coverage_area;
  ivec4 tiles;  // x: the tile list's first entry for this dispatch (compose/tile_lists.glsl)
};
layout(push_constant) uniform Params { ParamsConstants params_block; };
ParamsConstants params;

#define MRGI_UPLOAD_COLOR_ONLY
#include "common/upload_gather.glsl"

uvec3 camera_bytes(ivec2 p) {
  ivec2 size = frame.color_depth_size.xy;
  p = clamp(p, ivec2(0), size - 1);
  return color_rgb8(uint(p.y * size.x + p.x));
}

vec3 camera_linear(ivec2 p) { return srgb_decode(vec3(camera_bytes(p)) / 255.0f); }

// Camera colour at an output pixel, linear; bilinear on linear values when the sizes differ.
vec3 camera_at(vec2 rel, ivec2 pixel) {
  if (kSameSize) return camera_linear(pixel);
  vec2 cp = rel * vec2(frame.color_depth_size.xy) - 0.5f;
  ivec2 c0 = ivec2(floor(cp));
  vec2 f = cp - vec2(c0);
  return mix(mix(camera_linear(c0), camera_linear(c0 + ivec2(1, 0)), f.x),
             mix(camera_linear(c0 + ivec2(0, 1)), camera_linear(c0 + ivec2(1, 1)), f.x), f.y);
}

// Joint (mask-aware) up-sampling of the solutions from the internal resolution: the bilinear
// taps of the pixel, weighted by the bilinear weights of those on the pixel's own side of the
// virtual mask only, so a virtual pixel takes the object's lighting and a real pixel the real
// surface's, and the silhouette is the output-resolution coverage's, not the internal texels'.
// Taps come from the used extent only: texels outside it hold whatever an earlier level left
// (possibly NaN), and a weight of 0 would still make 0 * NaN = NaN.
struct Taps {
  ivec2 a, b;    // texels (a.x, a.y), (b.x, a.y), (a.x, b.y), (b.x, b.y)
  vec4 w;        // their weights, summing to 1
  bool no_side;  // no tap on the pixel's side: plain bilinear weights
};

// real_tile: no tap is virtual (kRealTiles), so the mask is not read.
Taps joint_taps(vec2 rel, ivec2 used, float is_virtual, bool real_tile) {
  vec2 ipos = rel * vec2(used) - 0.5f;
  ivec2 i0 = ivec2(floor(ipos));
  vec2 f = ipos - vec2(i0);
  Taps t;
  t.a = clamp(i0, ivec2(0), used - 1);
  t.b = clamp(i0 + 1, ivec2(0), used - 1);
  vec4 bilinear = vec4((1.0f - f.x) * (1.0f - f.y), f.x * (1.0f - f.y), (1.0f - f.x) * f.y, f.x * f.y);
  vec4 side = real_tile ? vec4(0.0f)
                        : vec4(imageLoad(virtual_position, ivec2(t.a.x, t.a.y)).w > 0.5f ? 1.0f : 0.0f,
                               imageLoad(virtual_position, ivec2(t.b.x, t.a.y)).w > 0.5f ? 1.0f : 0.0f,
                               imageLoad(virtual_position, ivec2(t.a.x, t.b.y)).w > 0.5f ? 1.0f : 0.0f,
                               imageLoad(virtual_position, ivec2(t.b.x, t.b.y)).w > 0.5f ? 1.0f : 0.0f);
  vec4 w = bilinear * (vec4(1.0f) - abs(side - vec4(is_virtual)));
  float sum = w.x + w.y + w.z + w.w;
  t.no_side = !(sum > 0.0f);
  t.w = t.no_side ? bilinear : w / sum;
  return t;
}

// (A macro: GLSL image parameters cannot carry the format qualifier imageLoad needs.)
#define SOLUTION_AT(NAME, S)                                                                  \
  vec3 NAME(Taps t, ivec2 pixel) {                                                           \
    if (kSameInternal) return finite3(imageLoad(S, pixel).rgb);                               \
    return finite3(imageLoad(S, ivec2(t.a.x, t.a.y)).rgb) * t.w.x +                           \
           finite3(imageLoad(S, ivec2(t.b.x, t.a.y)).rgb) * t.w.y +                           \
           finite3(imageLoad(S, ivec2(t.a.x, t.b.y)).rgb) * t.w.z +                           \
           finite3(imageLoad(S, ivec2(t.b.x, t.b.y)).rgb) * t.w.w;                            \
  }
SOLUTION_AT(solution_rv, lit_rv)
SOLUTION_AT(solution_r, lit_r)

void main() {
  frame = frame_ubo; params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = spread_invocation_id();
  ivec2 out_size = frame.internal_output_size.zw;
  if (kTiled) {
    int t = int(tiles.list[params.tiles.x + spread_workgroup_index_1d()]);
    int tiles_x = (out_size.x + 7) / 8;
    int ty = div_nonneg1(t, tiles_x);  // (a vector integer division is 8 scalar ones on lavapipe)
    pixel = ivec2(t - ty * tiles_x, ty) * 8 + ivec2(gl_LocalInvocationID.xy);
  }
  if (any(greaterThanEqual(pixel, out_size))) return;
  uint index = uint(pixel.y * out_size.x + pixel.x);
  vec2 rel = (vec2(pixel) + 0.5f) / vec2(out_size);
  if (kCameraOnly) {  // nothing virtual in view: the solutions were not computed
    if (kSameSize) {
      uvec3 c = camera_bytes(pixel);
      out_rgba8[index] = c.x | (c.y << 8u) | (c.z << 16u);
    } else {
      out_rgba8[index] = pack_output_word(srgb_encode(clamp(camera_at(rel, pixel), vec3(0.0f), vec3(1.0f))), false);
    }
    return;
  }
  ivec2 used = frame.internal_output_size.xy;
  float is_virtual;
  Taps taps;
  if (kRealTiles) {
    is_virtual = 0.0f;
    if (!kSameInternal) taps = joint_taps(rel, used, is_virtual, true);
  } else if (kSameInternal) {
    is_virtual = imageLoad(virtual_position, pixel).w > 0.5f ? 1.0f : 0.0f;
  } else {
    bool drawn = all(greaterThanEqual(pixel, params.coverage_area.xy)) && all(lessThan(pixel, params.coverage_area.zw));
    is_virtual = drawn && imageLoad(virtual_coverage, pixel).r > 0.5f ? 1.0f : 0.0f;
    taps = joint_taps(rel, used, is_virtual, false);
  }
  vec3 rv = solution_rv(taps, pixel);
  vec3 r = solution_r(taps, pixel);
  // A real pixel among virtual texels only (a gap in an object thinner than a texel): nothing
  // says how its light changes, so it keeps the camera's.
  if (!kSameInternal && taps.no_side && is_virtual < 0.5f) rv = r;
  vec3 encoded = compose_encoded(camera_at(rel, pixel), r, rv, is_virtual, frame.camera.y,
                                 params.compose.x, params.compose.y);
  out_rgba8[index] = pack_output_word(encoded, is_virtual > 0.5f);
}
