#version 460
// dir: the geometry-aware merge of the interleaved VPL shading (shade_vpl.comp; the DIR paper's
// Fig. 2 "merging" after the 4x4 split, Segovia et al. 2006): each pixel averages the indirect
// light of the 4x4 block of pixels around it (offsets -2..1: the 16 VPL subsets once each) that
// lie on its own surface (the same kind, real or virtual; normals within about 25 degrees;
// depths within 5 %), and adds it to the solutions baseline's direct light wrote (L_rv, L_r).
// Without interleaving (side 1) it adds the pixel's own value.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "dir/dir_params.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D indirect_rv;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D indirect_r;
layout(set = 0, binding = 7, rgba16f) uniform image2D lit_rv;
layout(set = 0, binding = 8, rgba16f) uniform image2D lit_r;
layout(push_constant) uniform Params { DirParams params_block; };
DirParams params;

const float kNormalCos = 0.9f;     // about 25 degrees
const float kDepthRelative = 0.05f;

// xyz: unit normal, w: camera depth (m) of the surface at q; w 0: none. Kind: 1 virtual, 0 real.
vec4 surface_at(ivec2 q, out int kind) {
  vec4 vp = imageLoad(virtual_position, q);
  if (vp.w > 0.5f) {
    kind = 1;
    vec3 n = imageLoad(virtual_normal, q).xyz;
    return vec4(normalize(n), distance(vp.xyz, frame.camera_world.xyz));
  }
  kind = 0;
  vec4 rp = imageLoad(real_position, q);
  if (!(rp.w > 0.0f)) return vec4(0.0f);
  vec3 n = imageLoad(real_normal, q).xyz;
  return vec4(length(n) > 0.0f ? normalize(n) : vec3(0.0f), distance(rp.xyz, frame.camera_world.xyz));
}

void main() {
  frame = frame_ubo; params = params_block;  // MRGI_UNIFORM_COPIES
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = frame.internal_output_size.xy;
  if (any(greaterThanEqual(pixel, size))) return;
  int kind;
  vec4 s = surface_at(pixel, kind);
  if (!(s.w > 0.0f)) return;
  vec3 sum_rv = vec3(0.0f), sum_r = vec3(0.0f);
  int side = params.vpls.w;
  if (side <= 1) {
    sum_rv = imageLoad(indirect_rv, pixel).rgb;
    sum_r = imageLoad(indirect_r, pixel).rgb;
  } else {
    float weight = 0.0f;
    int lo = -(side / 2);
    for (int y = lo; y < lo + side; ++y)
      for (int x = lo; x < lo + side; ++x) {
        ivec2 q = clamp(pixel + ivec2(x, y), ivec2(0), size - 1);
        int k;
        vec4 o = surface_at(q, k);
        if (k != kind || !(o.w > 0.0f) || dot(o.xyz, s.xyz) < kNormalCos ||
            abs(o.w - s.w) > kDepthRelative * s.w)
          continue;
        sum_rv += imageLoad(indirect_rv, q).rgb;
        sum_r += imageLoad(indirect_r, q).rgb;
        weight += 1.0f;
      }
    sum_rv /= max(weight, 1.0f);
    sum_r /= max(weight, 1.0f);
  }
  vec4 rv = imageLoad(lit_rv, pixel), r = imageLoad(lit_r, pixel);
  imageStore(lit_rv, pixel, vec4(clamp(rv.rgb + sum_rv, vec3(0.0f), vec3(60000.0f)), rv.a));
  imageStore(lit_r, pixel, vec4(clamp(r.rgb + sum_r, vec3(0.0f), vec3(60000.0f)), r.a));
}
