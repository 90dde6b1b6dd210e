#version 460
// ssrt radiance transfer (paper Sec. 5.1, 5.3): per cell of the (sub-sampled) image grid, SSDO
// visibility over the N directions of the cell's 2x2 jitter set, projected into SH (eq. 6 with
// the continuous K of eq. 7-9), and one-bounce indirect light from occluding samples (eq.
// 10-12). Computed twice in one pass with the same samples: for the real scene (receiver: the
// real surface, occluders: the real G-buffer) and for real + virtual (receiver: the visible
// surface, occluders: the closer of the real and virtual G-buffers), so where nothing virtual
// takes part the two solutions are bit-identical.
//
// Output layers of `coarse` (cell grid in the top-left corner):
//   0..3  T_real: 16 SH transfer coefficients of the real surface (for the light estimation)
//   4     x R_d = T_real . l, y R'_d = T_rv . l (luminance), z 1 real surface usable for the
//         light estimation (measured camera colour, green unclipped: see `usable`), w what the
//         cell sees: 0 nothing, 1 a real surface, 2 a virtual one (the up-sampling filters do
//         not mix the two)
//   5     rgb R_i (real only), w 1 surface present
//   6     rgb R'_i (real + virtual), w 1 surface present
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "ssrt/ssrt_math.h"
#include "ssrt/aux_views.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(std140, set = 0, binding = 1) uniform LightUbo { SsrtLight light; };
layout(std430, set = 0, binding = 2) readonly buffer SampleBuffer { SsrtSample samples[]; };
layout(set = 0, binding = 3) uniform sampler2D real_position;
layout(set = 0, binding = 4) uniform sampler2D real_normal;
layout(set = 0, binding = 5) uniform sampler2D real_albedo;
layout(set = 0, binding = 6) uniform sampler2D virtual_position;
layout(set = 0, binding = 7) uniform sampler2D virtual_normal;
layout(set = 0, binding = 8) uniform sampler2D virtual_albedo;
layout(set = 0, binding = 9, rgba32f) writeonly uniform image2DArray coarse;
// The volume's auxiliary orthographic layers (left, right, top, light; aux_views.glsl): occluders
// outside the camera frustum (paper Sec. 5.1).
layout(set = 0, binding = 10) uniform sampler2DArray aux_position;
layout(std140, set = 0, binding = 11) uniform AuxUbo { SsrtAuxViews aux; };
layout(push_constant) uniform Push {
  ivec4 grid;     // x, y cells; z step in pixels; w directions N
  ivec4 config;   // x first sample of the level's sets, y SH bands, z/w unused
  vec4 sampling;  // x radius (m), y chi, z normal offset (m), w minimum sender distance (m)
  vec4 bounce;    // x sample area (m^2), y saturation threshold, z depth test bias (fraction),
                  // w occluder range (m)
  ivec4 influence;  // cells [x0, x1) x [y0, y1) that the virtual objects' influence region covers
  vec4 aux_test;    // x depth bias in texels of each aux layer, y 1 = test the aux layers
} pc;

// Paper Fig. 5a: a sample the main buffer finds visible may lie behind a surface one of the
// auxiliary buffers sees. Returns true with that surface's world position (the first layer
// that occludes; its surface must lie within the occluder range of the receiver x).
bool aux_occluder(vec3 x, vec3 y, out vec3 s) {
  s = vec3(0.0f);
  if (pc.aux_test.y < 0.5f) return false;
  for (int i = 0; i < aux.info.x; ++i) {
    ivec2 texel;
    float depth;
    if (!ssrt_aux_texel(aux.world_to_aux[i], aux.info.y, y, texel, depth)) continue;
    vec4 o = texelFetch(aux_position, ivec3(texel, i), 0);
    vec3 d = o.xyz - x;
    if (o.w > 0.0f && o.w < depth - pc.aux_test.x * aux.extent[i].z &&
        dot(d, d) <= pc.bounce.w * pc.bounce.w) {
      s = o.xyz;
      return true;
    }
  }
  return false;
}

// Camera-space depth of a world point.
float view_depth(vec3 p) { return (frame.world_to_camera * vec4(p, 1.0f)).z; }

void main() {
  ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
  if (cell.x >= pc.grid.x || cell.y >= pc.grid.y) return;
  ivec2 size = frame.internal_output_size.xy;
  int step = pc.grid.z;
  ivec2 pixel = min(cell * step + ivec2(step / 2), size - ivec2(1));

  vec4 rp = texelFetch(real_position, pixel, 0);
  vec4 vp = texelFetch(virtual_position, pixel, 0);
  bool real_ok = rp.w > 0.0f;
  bool virt = vp.w > 0.5f;
  vec4 zero = vec4(0.0f);
  if (!real_ok && !virt) {
    for (int l = 0; l < 7; ++l) imageStore(coarse, ivec3(cell, l), zero);
    return;
  }
  vec3 xr = rp.xyz;
  vec3 nr = normalize(texelFetch(real_normal, pixel, 0).xyz + vec3(1e-9f));
  vec3 xv = virt ? vp.xyz : xr;
  vec3 nv = virt ? normalize(texelFetch(virtual_normal, pixel, 0).xyz + vec3(1e-9f)) : nr;

  vec4 t_real[4] = vec4[4](zero, zero, zero, zero);
  vec4 t_rv[4] = vec4[4](zero, zero, zero, zero);
  vec3 ri = vec3(0.0f), ri_v = vec3(0.0f);
  vec3 l_dir = light.dominant.xyz;
  vec3 e_light = light.dominant.w > 0.5f ? light.dominant_irradiance.rgb : vec3(0.0f);
  float chi = pc.sampling.y;
  float bias = pc.bounce.z;
  int set = (cell.x & 1) + 2 * (cell.y & 1);
  // Outside the projected influence region nothing virtual lies within the occluder range of
  // this surface, and the range check below makes sure only occluders within that range count,
  // so the real + virtual solution equals the real one bit for bit: it is copied, not computed
  // (DESIGN.md: tiles outside the influence region are not shaded).
  bool influenced = virt || (cell.x >= pc.influence.x && cell.x < pc.influence.z &&
                             cell.y >= pc.influence.y && cell.y < pc.influence.w);
  int base = pc.config.x + set * pc.grid.w;

  for (int j = 0; j < pc.grid.w; ++j) {
    SsrtSample s = samples[base + j];
    vec3 w = s.direction_and_radius.xyz;
    float r = s.direction_and_radius.w * pc.sampling.x;
    bool do_real = real_ok && dot(nr, w) > 0.0f;
    bool do_rv = influenced && dot(nv, w) > 0.0f && (virt || real_ok);
    if (!do_real && !do_rv) continue;

    // Real receiver against real occluders.
    if (do_real) {
      vec3 y = xr + nr * pc.sampling.z + w * r;
      float k = 1.0f;
      vec3 sp = vec3(0.0f), sn = vec3(0.0f), sa = vec3(0.0f);
      float yz = view_depth(y);
      if (yz > 0.0f) {
        vec2 q = project_pinhole((frame.world_to_camera * vec4(y, 1.0f)).xyz, frame.internal_k);
        ivec2 qi = ivec2(floor(q + 0.5f));
        if (all(greaterThanEqual(qi, ivec2(0))) && all(lessThan(qi, size))) {
          vec4 o = texelFetch(real_position, qi, 0);
          // Range check (standard SSDO/SSAO practice; the paper does not say): a surface
          // farther from x than the range (push: twice the sampling radius, since the surface
          // seen in front of y may lie well in front of it) is not what blocks this direction.
          vec3 dr = o.xyz - xr;
          if (o.w > 0.0f && o.w < yz * (1.0f - bias) && dot(dr, dr) <= pc.bounce.w * pc.bounce.w) {
            sp = o.xyz;
            sn = texelFetch(real_normal, qi, 0).xyz;
            sa = texelFetch(real_albedo, qi, 0).rgb;
            k = ssrt_visibility_k(xr, sp, w, chi);
          }
        }
      }
      // Occluders the view cannot see: visibility only (their normal and colour are unknown,
      // so they send no indirect light).
      vec3 s_aux;
      bool from_view = k < 1.0f;
      if (!from_view && aux_occluder(xr, y, s_aux)) k = ssrt_visibility_k(xr, s_aux, w, chi);
      float tw = ssrt_transfer_weight(nr, w, k, 1.0f);
      for (int c = 0; c < 4; ++c) t_real[c] += tw * s.sh_weights[c];
      if (from_view) {
        ri += ssrt_indirect_term(xr, nr, sp, sn, sa, k, l_dir, e_light, pc.bounce.x,
                                 pc.sampling.w);
      }
    }
    // Visible receiver against real + virtual occluders.
    if (do_rv) {
      vec3 y = xv + nv * pc.sampling.z + w * r;
      float k = 1.0f;
      vec3 sp = vec3(0.0f), sn = vec3(0.0f), sa = vec3(0.0f);
      float yz = view_depth(y);
      if (yz > 0.0f) {
        vec2 q = project_pinhole((frame.world_to_camera * vec4(y, 1.0f)).xyz, frame.internal_k);
        ivec2 qi = ivec2(floor(q + 0.5f));
        if (all(greaterThanEqual(qi, ivec2(0))) && all(lessThan(qi, size))) {
          vec4 ov = texelFetch(virtual_position, qi, 0);
          vec4 o = texelFetch(real_position, qi, 0);
          // The virtual G-buffer only holds virtual surfaces in front of the real one.
          bool use_virtual = ov.w > 0.5f;
          float oz = use_virtual ? view_depth(ov.xyz) : o.w;
          vec3 dv = (use_virtual ? ov.xyz : o.xyz) - xv;
          if ((use_virtual || o.w > 0.0f) && oz > 0.0f && oz < yz * (1.0f - bias) &&
              dot(dv, dv) <= pc.bounce.w * pc.bounce.w) {
            sp = use_virtual ? ov.xyz : o.xyz;
            sn = use_virtual ? texelFetch(virtual_normal, qi, 0).xyz : texelFetch(real_normal, qi, 0).xyz;
            sa = use_virtual ? texelFetch(virtual_albedo, qi, 0).rgb : texelFetch(real_albedo, qi, 0).rgb;
            k = ssrt_visibility_k(xv, sp, w, chi);
          }
        }
      }
      vec3 sv_aux;
      bool from_view_v = k < 1.0f;
      if (!from_view_v && aux_occluder(xv, y, sv_aux)) k = ssrt_visibility_k(xv, sv_aux, w, chi);
      float tw = ssrt_transfer_weight(nv, w, k, 1.0f);
      for (int c = 0; c < 4; ++c) t_rv[c] += tw * s.sh_weights[c];
      if (from_view_v) {
        ri_v += ssrt_indirect_term(xv, nv, sp, sn, sa, k, l_dir, e_light, pc.bounce.x,
                                   pc.sampling.w);
      }
    }
  }

  if (!influenced) {
    t_rv = t_real;
    ri_v = ri;
  }
  // Bands above the level's count are dropped (their coefficients stay 0 in the light too).
  int n = pc.config.y * pc.config.y;
  float rd = 0.0f, rd_v = 0.0f;
  for (int i = 0; i < 16; ++i) {
    if (i >= n) break;
    vec4 a = t_real[i / 4], b = t_rv[i / 4];
    int k = i - 4 * (i / 4);
    float ta = k == 0 ? a.x : (k == 1 ? a.y : (k == 2 ? a.z : a.w));
    float tb = k == 0 ? b.x : (k == 1 ? b.y : (k == 2 ? b.z : b.w));
    rd += ta * light.sh[i].w;
    rd_v += tb * light.sh[i].w;
  }
  // Usable for the light estimation: the camera measured this pixel (recon's alpha; the volume's
  // G-buffer also fills pixels the depth camera missed, whose recon colour is 0 and read as a
  // black surface: 500 such cells at env_fisheye's far floor pulled the estimate down), and the
  // green channel, 72 % of the luminance, is below clipping. A warm sun clips red first on a
  // bright grey ball; rejecting such pixels removed exactly the surfaces facing the light.
  vec4 camera = texelFetch(real_albedo, pixel, 0);
  float usable = real_ok && camera.a > 0.5f && camera.g < pc.bounce.y ? 1.0f : 0.0f;
  for (int c = 0; c < 4; ++c) imageStore(coarse, ivec3(cell, c), real_ok ? t_real[c] : zero);
  imageStore(coarse, ivec3(cell, 4), vec4(max(rd, 0.0f), max(rd_v, 0.0f), usable, virt ? 2.0f : 1.0f));
  imageStore(coarse, ivec3(cell, 5), vec4(ri, 1.0f));
  imageStore(coarse, ivec3(cell, 6), vec4(ri_v, 1.0f));
}
