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
//   4     x R_d, y R'_d: T . l (luminance), summed per sample as weight x L(w) (see rd_sum),
//         z 1 real surface usable for the
//         light estimation (measured camera colour, green unclipped: see `usable`), w what the
//         cell sees: 0 nothing, 1 a real surface, 2 a virtual one (the up-sampling filters do
//         not mix the two)
//   5     rgb R_i (real only), w 1 surface present
//   6     rgb R'_i (real + virtual), w 1 surface present
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "shared/transfer_math.h"
#include "ssrt/aux_views.glsl"
#include "common/workgroup_order.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// kRealReceivers: the dispatch covers only cells whose receiver is real (outside the virtual
// objects' projected bounds), so both solutions share the receiver, the sample point and every
// lookup at it: one real G-buffer read, one virtual G-buffer read, one aux test and one SH basis
// per sample instead of two of each (lavapipe pays for every instruction of every lane, so
// halving the reads is the only way to save them). Same results as the general path, which
// runs over the cells inside those bounds.
layout(constant_id = 0) const bool kRealReceivers = false;
// kRealOnly (with kRealReceivers): the dispatch covers only cells outside the influence region,
// whose real + virtual solution is the real one bit for bit (see `influenced` in main): only the
// real solution is computed, and nothing of the virtual G-buffer is read. Most of a frame lies
// outside the region when the virtual objects are small on screen.
layout(constant_id = 1) const bool kRealOnly = false;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform LightUbo { SsrtLight light; };
// Every level's jitter sets, set-major (xyz unit direction, w displacement / radius; ssrt_init.cpp
// says why a uniform buffer).
layout(std140, set = 0, binding = 2) uniform SampleDirections {
  vec4 sample_directions[SSRT_MAX_SAMPLE_DIRECTIONS];
};
// Storage images read with imageLoad: on lavapipe a sampled texelFetch costs 2-3x as much.
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D real_normal;
// The receiver (the cell's centre pixel) is read from the real G-buffer (3, 4), the
// full-resolution buffers 6-7 and 5, 13 (the camera's colour and depth as uploaded,
// upload_gather.glsl); what a sample lands on from the packed occluder G-buffer
// (occluders.comp: 8 and 12).
layout(set = 0, binding = 5, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words, one a pixel
layout(set = 0, binding = 13, r32ui) readonly uniform uimageBuffer depth_words;  // u16 pairs
#include "common/upload_gather.glsl"
layout(set = 0, binding = 6, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 8, rgba32ui) readonly uniform uimage2D occ_a;
layout(set = 0, binding = 9, rgba32f) writeonly uniform image2DArray coarse;
// The volume's auxiliary orthographic layers (left, right, top, light; aux_views.glsl): occluders
// outside the camera frustum (paper Sec. 5.1).
layout(set = 0, binding = 10, rgba32f) readonly uniform image2DArray aux_position;
layout(std140, set = 0, binding = 11) uniform AuxUbo { SsrtAuxViews aux; };
layout(set = 0, binding = 12, rg32ui) readonly uniform uimage2D occ_b;
struct PushConstants {
  ivec4 grid;     // x, y cells; z step in pixels; w directions N
  ivec4 config;   // x first sample of the level's sets, y SH bands, z geometry step (internal
                  // pixels per texel of real_position / real_normal), w occluder step (of
                  // occ_a / occ_b)
  vec4 sampling;  // x radius (m), y chi, z normal offset (m), w minimum sender distance (m)
  vec4 bounce;    // x sample area (m^2), y saturation threshold, z depth test bias (fraction),
                  // w occluder range (m)
  ivec4 influence;  // cells [x0, x1) x [y0, y1) that the virtual objects' influence region covers
  vec4 aux_test;    // x depth bias in texels of each aux layer, y 1 = test the aux layers,
                    // z solid angle of one sample (4 pi / N)
  ivec4 region;     // cells [x0, x1) x [y0, y1) of this dispatch
};
layout(push_constant) uniform Push { PushConstants pc_block; };
PushConstants pc;
// The aux layers' values the sample loop reads, copied on main's first line like the blocks
// above (SsrtAuxViews holds arrays: a private copy of the whole struct went to per-lane scratch
// memory, allocated and cleared on every dispatch). g_aux_bias: the depth bias (m) of the left,
// right, top and light layer.
mat4 g_aux_left, g_aux_top, g_aux_light;
vec4 g_aux_bias;
int g_aux_layers, g_aux_texels;

// Paper Fig. 5a: a sample the main buffer finds visible may lie behind a surface one of the
// auxiliary buffers sees. Returns true with that surface's world position (the first layer
// that occludes, in layer order; its surface must lie within the occluder range of the
// receiver x). `y_camera_x`: y's camera-space x.
// The left and right layers share the image plane through the camera centre and look along
// -x and +x (volume.cpp make_views): y lies in front of the left one exactly when its camera x
// is negative, else of the right one (or of neither, on the plane), so one lookup with that
// layer's matrix stands for both (on lavapipe every layer costs its whole test for every lane,
// taken or not: three tests instead of four). The matrices are chosen per lane by selects of
// uniform columns; with a constant layer index lavapipe reads a matrix once per SIMD chunk,
// with a loop or lane index it gathers it per lane.
bool aux_layer_hit_at(vec3 p, int layer, float bias_m, vec3 x, out vec3 s) {
  ivec2 texel;
  float depth;
  bool in_layer = layer < g_aux_layers && ssrt_aux_texel_at(p, g_aux_texels, texel, depth);
  vec4 o = imageLoad(aux_position, ivec3(texel, layer));
  vec3 d = o.xyz - x;
  s = o.xyz;
  return in_layer && o.w > 0.0f && o.w < depth - bias_m && dot(d, d) <= pc.bounce.w * pc.bounce.w;
}

bool aux_occluder(vec3 x, vec3 y, float y_camera_x, out vec3 s) {
  s = vec3(0.0f);
  if (pc.aux_test.y < 0.5f) return false;
  bool right = y_camera_x > 0.0f;
  int side = right ? SSRT_AUX_RIGHT : SSRT_AUX_LEFT;
  // The right layer mirrors the left one (same image plane and down axis, opposite right and
  // forward axes: volume.cpp make_views), so y's coordinates in it are (1 - u, v, -depth) of
  // its left ones: one uniform matrix instead of a per-lane choice of two.
  vec3 p_left = (g_aux_left * vec4(y, 1.0f)).xyz;
  vec3 p_side = right ? vec3(1.0f - p_left.x, p_left.y, -p_left.z) : p_left;
  float side_bias = right ? g_aux_bias.y : g_aux_bias.x;
  vec3 s_side, s_top, s_light;
  bool hit_side = aux_layer_hit_at(p_side, side, side_bias, x, s_side);
  bool hit_top = aux_layer_hit_at((g_aux_top * vec4(y, 1.0f)).xyz, SSRT_AUX_TOP, g_aux_bias.z, x,
                                  s_top);
  bool hit_light = aux_layer_hit_at((g_aux_light * vec4(y, 1.0f)).xyz, SSRT_AUX_LIGHT,
                                    g_aux_bias.w, x, s_light);
  s = hit_side ? s_side : (hit_top ? s_top : (hit_light ? s_light : s));
  return hit_side || hit_top || hit_light;
}

// What a sample sees at internal pixel position q (qi its nearest pixel), from the packed
// occluder G-buffer (occluders.comp): the real surface (xyz world, w camera depth; 0 = none), its
// world normal rn and camera colour ra; the virtual surface in front of it (same form, all 0
// where none), its normal vn and albedo va. Positions are rebuilt from the depths: the real one
// at the centre of its geometry texel (gstep pixels a side), the virtual one at the occluder
// texel's sample pixel. Coarser than a pixel, the point of the texel's tangent plane on q's
// camera ray (tangent_plane_depth): a sample that projects 2 px from the texel centre on a sloped
// floor would otherwise read the centre's depth, several per cent off, and the occluder bias
// would find the receiver blocked by its own surface.
void surfaces_at(vec2 q, ivec2 qi, int gstep, int ostep, out vec4 real, out vec3 rn,
                 out vec3 ra, out vec4 virt, out vec3 vn, out vec3 va) {
  ivec2 g = div_nonneg(qi, ostep);
  uvec4 a = imageLoad(occ_a, g);
  uvec2 b = kRealOnly ? uvec2(0u) : imageLoad(occ_b, g).xy;
  ivec2 p = min(g * ostep + ivec2(ostep / 2), frame.internal_output_size.xy - 1);
  vec3 ray = unproject_pinhole(q, 1.0f, frame.internal_k);
  mat3 to_camera = mat3(frame.world_to_camera);

  float zr = uintBitsToFloat(a.x);
  rn = oct_decode(unpackSnorm2x16(a.y));
  ra = unpackUnorm4x8(a.z).rgb;
  ivec2 gt = div_nonneg(p, gstep);
  vec2 centre = vec2(gt * gstep) + 0.5f * float(gstep - 1);
  vec3 pr = unproject_pinhole(centre, zr, frame.internal_k);
  float z = gstep > 1 ? tangent_plane_depth(ray, pr, to_camera * rn, MRGI_DEPTH_EDGE_RELATIVE) : zr;
  vec3 cr = gstep > 1 ? ray * z : pr;
  real = zr > 0.0f ? vec4((frame.camera_to_world * vec4(cr, 1.0f)).xyz, z) : vec4(0.0f);

  virt = vec4(0.0f);
  vn = vec3(0.0f);
  va = vec3(0.0f);
  if (kRealOnly) return;
  float zv = uintBitsToFloat(a.w);
  vn = oct_decode(unpackSnorm2x16(b.x));
  va = unpackUnorm4x8(b.y).rgb;
  vec3 pv = unproject_pinhole(vec2(p), zv, frame.internal_k);
  float z_v = ostep > 1 ? tangent_plane_depth(ray, pv, to_camera * vn, MRGI_DEPTH_EDGE_RELATIVE) : zv;
  vec3 cv = ostep > 1 ? ray * z_v : pv;
  virt = zv > 0.0f ? vec4((frame.camera_to_world * vec4(cv, 1.0f)).xyz, z_v) : vec4(0.0f);
}

// Camera-space depth of a world point.
float view_depth(vec3 p) { return (frame.world_to_camera * vec4(p, 1.0f)).z; }

void main() {
  frame = frame_ubo; pc = pc_block;  // MRGI_UNIFORM_COPIES
  g_aux_left = aux.world_to_aux[SSRT_AUX_LEFT];
  g_aux_top = aux.world_to_aux[SSRT_AUX_TOP];
  g_aux_light = aux.world_to_aux[SSRT_AUX_LIGHT];
  g_aux_bias = pc.aux_test.x * vec4(aux.extent[SSRT_AUX_LEFT].z, aux.extent[SSRT_AUX_RIGHT].z,
                                    aux.extent[SSRT_AUX_TOP].z, aux.extent[SSRT_AUX_LIGHT].z);
  g_aux_layers = aux.info.x;
  g_aux_texels = aux.info.y;
  // Bands above the level's count are dropped (their coefficients stay 0 in the light too).
  int n_sh = pc.config.y * pc.config.y;
  SH16 l_sh;
  l_sh.c0 = vec4(light.sh[0].w, n_sh > 1 ? light.sh[1].w : 0.0f, n_sh > 2 ? light.sh[2].w : 0.0f,
                 n_sh > 3 ? light.sh[3].w : 0.0f);
  l_sh.c1 = vec4(n_sh > 4 ? light.sh[4].w : 0.0f, n_sh > 5 ? light.sh[5].w : 0.0f,
                 n_sh > 6 ? light.sh[6].w : 0.0f, n_sh > 7 ? light.sh[7].w : 0.0f);
  l_sh.c2 = vec4(n_sh > 8 ? light.sh[8].w : 0.0f, n_sh > 9 ? light.sh[9].w : 0.0f,
                 n_sh > 10 ? light.sh[10].w : 0.0f, n_sh > 11 ? light.sh[11].w : 0.0f);
  l_sh.c3 = vec4(n_sh > 12 ? light.sh[12].w : 0.0f, n_sh > 13 ? light.sh[13].w : 0.0f,
                 n_sh > 14 ? light.sh[14].w : 0.0f, n_sh > 15 ? light.sh[15].w : 0.0f);
  vec3 l_dir = light.dominant.xyz;
  vec3 e_light = light.dominant.w > 0.5f ? light.dominant_irradiance.rgb : vec3(0.0f);
  ivec2 cell = pc.region.xy + spread_invocation_id();
  if (cell.x >= pc.region.z || cell.y >= pc.region.w) return;
  ivec2 size = frame.internal_output_size.xy;
  int step = pc.grid.z;
  ivec2 pixel = min(cell * step + ivec2(step / 2), size - ivec2(1));

  int gstep = pc.config.z;
  int ostep = pc.config.w;
  vec4 rp = imageLoad(real_position, div_nonneg(pixel, gstep));
  vec4 vp = imageLoad(virtual_position, pixel);
  bool real_ok = rp.w > 0.0f;
  bool virt = vp.w > 0.5f;
  vec4 zero = vec4(0.0f);
  if (!real_ok && !virt) {
    for (int l = 0; l < 7; ++l) imageStore(coarse, ivec3(cell, l), zero);
    return;
  }
  vec3 xr = rp.xyz;
  vec3 nr = normalize(imageLoad(real_normal, div_nonneg(pixel, gstep)).xyz + vec3(1e-9f));
  if (kRealReceivers) virt = false;  // the host's bounds say so; a stray coverage bit must not
                                     // change the solution between the two paths
  vec3 xv = virt ? vp.xyz : xr;
  vec3 nv = virt ? normalize(imageLoad(virtual_normal, pixel).xyz + vec3(1e-9f)) : nr;

  // T_real, the 16 SH transfer coefficients the light estimation needs. R_d and R'_d are
  // T . l, and T . l = sum over samples of weight x L(w), L(w) = l . Y(w) the current light's
  // radiance from the sample's direction: each solution accumulates that one product per sample
  // (rd_sum, rd_v_sum), so the real + virtual solution keeps no 16 coefficients of its own
  // (16 accumulators per lane fewer: on a CPU device they spill; 16 multiply-adds become one).
  // Both sums take the same terms in the same order where nothing virtual takes part, so R'_d
  // equals R_d bit for bit there, as the up-sampling's tile test needs.
  vec4 t_real[4] = vec4[4](zero, zero, zero, zero);
  float rd_sum = 0.0f, rd_v_sum = 0.0f;
  vec3 ri = vec3(0.0f), ri_v = vec3(0.0f);
  float chi = pc.sampling.y;
  float bias = pc.bounce.z;
  int set = (cell.x & 1) + 2 * (cell.y & 1);
  // Outside the projected influence region nothing virtual lies within the occluder range of
  // this surface, and the range check below makes sure only occluders within that range count,
  // so the real + virtual solution equals the real one bit for bit: it is copied, not computed
  // (docs/DESIGN.md: tiles outside the influence region are not shaded).
  bool influenced = !kRealOnly && (virt || (cell.x >= pc.influence.x && cell.x < pc.influence.z &&
                             cell.y >= pc.influence.y && cell.y < pc.influence.w));
  int base = pc.config.x + set * pc.grid.w;

  // Each set holds antipodal pairs (sample j + N/2 = -sample j, sample_directions.h), so exactly
  // one of a pair faces any normal: the loop runs over the N/2 pairs and takes the member in
  // the receiver's hemisphere, with its own displacement. The sum is the one over all N samples
  // whose back-facing half contributes 0; lavapipe runs a skipped sample's body under a lane
  // mask, so looping over all N paid for both halves. The SH basis of the direction is
  // evaluated here (sh_basis16, the function that made the buffer's weights) and the solid
  // angle applied once at the end: a lane's 16 weights were a gather of 16 floats per sample on
  // lavapipe, about a quarter of this pass.
  int half_n = pc.grid.w / 2;
  if (kRealReceivers) {
    float range2 = pc.bounce.w * pc.bounce.w;
    for (int j = 0; j < half_n; ++j) {
      vec4 dr = sample_directions[base + j];
      float r_anti = sample_directions[base + j + half_n].w;
      bool flip = dot(nr, dr.xyz) < 0.0f;
      vec3 w = flip ? -dr.xyz : dr.xyz;
      float r = (flip ? r_anti : dr.w) * pc.sampling.x;
      if (!(real_ok && dot(nr, w) > 0.0f)) continue;
      vec3 y = xr + nr * pc.sampling.z + w * r;
      vec3 yc = (frame.world_to_camera * vec4(y, 1.0f)).xyz;
      float yz = yc.z;
      vec2 q = project_pinhole(yc, frame.internal_k);
      ivec2 qi = ivec2(floor(q + 0.5f));
      bool in_view = yz > 0.0f && all(greaterThanEqual(qi, ivec2(0))) && all(lessThan(qi, size));
      qi = clamp(qi, ivec2(0), size - 1);
      vec3 on, vn, va, oa;
      vec4 o, ov;
      surfaces_at(q, qi, gstep, ostep, o, on, oa, ov, vn, va);
      // Real scene: the real surface in front of the sample within the range (see the general
      // path below for the rules); real + virtual: the virtual surface where the virtual
      // G-buffer holds one (it is in front of the real one there), else the real one.
      // Each sender's direction and distance once (ssrt_sender): the range check, K and the
      // bounce term all start from them.
      SsrtSender sd_r = ssrt_sender(xr, o.xyz);
      SsrtSender sd_vo = ssrt_sender(xr, ov.xyz);
      bool hit_r = in_view && o.w > 0.0f && o.w < yz * (1.0f - bias) && sd_r.len2 <= range2;
      bool use_virtual = in_view && influenced && ov.w > 0.0f;
      float oz_v = ov.w;
      bool hit_vo = oz_v > 0.0f && oz_v < yz * (1.0f - bias) && sd_vo.len2 <= range2;
      bool hit_v = use_virtual ? hit_vo : hit_r;
      SsrtSender sd_v = use_virtual ? sd_vo : sd_r;
      float k = hit_r ? ssrt_visibility_k_from(sd_r, w, chi) : 1.0f;
      float k_v = hit_v ? ssrt_visibility_k_from(sd_v, w, chi) : 1.0f;
      bool from_view = k < 1.0f, from_view_v = k_v < 1.0f;
      vec3 s_aux;
      bool aux_hit = aux_occluder(xr, y, yc.x, s_aux);
      float k_aux = ssrt_visibility_k(xr, s_aux, w, chi);
      if (!from_view && aux_hit) k = k_aux;
      if (!from_view_v && aux_hit) k_v = k_aux;
      SH16 y_sh = sh_basis16(w);
      float l_w = sh_dot(y_sh, l_sh);
      float tw = ssrt_transfer_weight(nr, w, k, 1.0f);
      t_real[0] += tw * y_sh.c0;
      t_real[1] += tw * y_sh.c1;
      t_real[2] += tw * y_sh.c2;
      t_real[3] += tw * y_sh.c3;
      rd_sum += tw * l_w;
      if (from_view)
        ri += ssrt_indirect_term_from(sd_r, nr, on, oa, k, l_dir, e_light, pc.bounce.x,
                                      pc.sampling.w);
      if (kRealOnly) continue;
      float tw_v = ssrt_transfer_weight(nr, w, k_v, 1.0f);
      rd_v_sum += tw_v * l_w;
      vec3 sn_v = use_virtual ? vn : on;
      vec3 sa_v = use_virtual ? va : oa;
      if (from_view_v)
        ri_v += ssrt_indirect_term_from(sd_v, nr, sn_v, sa_v, k_v, l_dir, e_light, pc.bounce.x,
                                        pc.sampling.w);
    }
  } else {
    for (int j = 0; j < half_n; ++j) {
      vec4 dr = sample_directions[base + j];
      float r_anti = sample_directions[base + j + half_n].w;
      vec3 w0 = dr.xyz;
      bool flip_r = dot(nr, w0) < 0.0f;
      bool flip_v = dot(nv, w0) < 0.0f;
      vec3 w_r = flip_r ? -w0 : w0;
      vec3 w_v = flip_v ? -w0 : w0;
      float r_r = (flip_r ? r_anti : dr.w) * pc.sampling.x;
      float r_v = (flip_v ? r_anti : dr.w) * pc.sampling.x;
      bool do_real = real_ok && dot(nr, w_r) > 0.0f;
      bool do_rv = influenced && dot(nv, w_v) > 0.0f && (virt || real_ok);

      // Real receiver against real occluders.
      if (do_real) {
        vec3 w = w_r;
        vec3 y = xr + nr * pc.sampling.z + w * r_r;
        float k = 1.0f;
        vec3 sn = vec3(0.0f), sa = vec3(0.0f);
        SsrtSender sd = ssrt_sender(xr, xr);  // none yet (degenerate: sends nothing)
        vec3 yc = (frame.world_to_camera * vec4(y, 1.0f)).xyz;
        float yz = yc.z;
        if (yz > 0.0f) {
          vec2 q = project_pinhole(yc, frame.internal_k);
          ivec2 qi = ivec2(floor(q + 0.5f));
          if (all(greaterThanEqual(qi, ivec2(0))) && all(lessThan(qi, size))) {
            vec3 on, vn, va, ra;
            vec4 o, ov;
            surfaces_at(q, qi, gstep, ostep, o, on, ra, ov, vn, va);
            // Range check (standard SSDO/SSAO practice; the paper does not say): a surface
            // farther from x than the range (push: twice the sampling radius, since the surface
            // seen in front of y may lie well in front of it) is not what blocks this direction.
            SsrtSender so = ssrt_sender(xr, o.xyz);
            if (o.w > 0.0f && o.w < yz * (1.0f - bias) && so.len2 <= pc.bounce.w * pc.bounce.w) {
              sd = so;
              sn = on;
              sa = ra;
              k = ssrt_visibility_k_from(sd, w, chi);
            }
          }
        }
        // Occluders the view cannot see: visibility only (their normal and colour are unknown,
        // so they send no indirect light).
        vec3 s_aux;
        bool from_view = k < 1.0f;
        if (!from_view && aux_occluder(xr, y, yc.x, s_aux)) k = ssrt_visibility_k(xr, s_aux, w, chi);
        float tw = ssrt_transfer_weight(nr, w, k, 1.0f);
        SH16 y_sh = sh_basis16(w);
        t_real[0] += tw * y_sh.c0;
        t_real[1] += tw * y_sh.c1;
        t_real[2] += tw * y_sh.c2;
        t_real[3] += tw * y_sh.c3;
        rd_sum += tw * sh_dot(y_sh, l_sh);
        if (from_view) {
          ri += ssrt_indirect_term_from(sd, nr, sn, sa, k, l_dir, e_light, pc.bounce.x,
                                        pc.sampling.w);
        }
      }
      // Visible receiver against real + virtual occluders.
      if (do_rv) {
        vec3 w = w_v;
        vec3 y = xv + nv * pc.sampling.z + w * r_v;
        float k = 1.0f;
        vec3 sn = vec3(0.0f), sa = vec3(0.0f);
        SsrtSender sd = ssrt_sender(xv, xv);  // none yet (degenerate: sends nothing)
        vec3 yc = (frame.world_to_camera * vec4(y, 1.0f)).xyz;
        float yz = yc.z;
        if (yz > 0.0f) {
          vec2 q = project_pinhole(yc, frame.internal_k);
          ivec2 qi = ivec2(floor(q + 0.5f));
          if (all(greaterThanEqual(qi, ivec2(0))) && all(lessThan(qi, size))) {
            vec3 on, vn, va, ra;
            vec4 o, ov;
            surfaces_at(q, qi, gstep, ostep, o, on, ra, ov, vn, va);
            // The virtual G-buffer only holds virtual surfaces in front of the real one.
            bool use_virtual = ov.w > 0.0f;
            float oz = use_virtual ? ov.w : o.w;
            SsrtSender so = ssrt_sender(xv, use_virtual ? ov.xyz : o.xyz);
            if ((use_virtual || o.w > 0.0f) && oz > 0.0f && oz < yz * (1.0f - bias) &&
                so.len2 <= pc.bounce.w * pc.bounce.w) {
              sd = so;
              sn = use_virtual ? vn : on;
              sa = use_virtual ? va : ra;
              k = ssrt_visibility_k_from(sd, w, chi);
            }
          }
        }
        vec3 sv_aux;
        bool from_view_v = k < 1.0f;
        if (!from_view_v && aux_occluder(xv, y, yc.x, sv_aux)) k = ssrt_visibility_k(xv, sv_aux, w, chi);
        float tw = ssrt_transfer_weight(nv, w, k, 1.0f);
        rd_v_sum += tw * sh_dot(sh_basis16(w), l_sh);
        if (from_view_v) {
          ri_v += ssrt_indirect_term_from(sd, nv, sn, sa, k, l_dir, e_light, pc.bounce.x,
                                          pc.sampling.w);
        }
      }
    }
  }
  for (int c = 0; c < 4; ++c) t_real[c] *= pc.aux_test.z;  // the solid angle of one sample, 4 pi / N
  float rd = rd_sum * pc.aux_test.z, rd_v = rd_v_sum * pc.aux_test.z;
  if (!influenced) {
    rd_v = rd;
    ri_v = ri;
  }
  // Usable for the light estimation: the camera measured this pixel (recon's alpha; the volume's
  // G-buffer also fills pixels the depth camera missed, whose recon colour is 0 and read as a
  // black surface: 500 such cells at env_fisheye's far floor pulled the estimate down), and the
  // green channel, 72 % of the luminance, is below clipping. A warm sun clips red first on a
  // bright grey ball; rejecting such pixels removed exactly the surfaces facing the light.
  vec4 camera = camera_at(vec2(pixel));
  float usable = real_ok && camera.a > 0.5f && camera.g < pc.bounce.y ? 1.0f : 0.0f;
  for (int c = 0; c < 4; ++c) imageStore(coarse, ivec3(cell, c), real_ok ? t_real[c] : zero);
  imageStore(coarse, ivec3(cell, 4), vec4(max(rd, 0.0f), max(rd_v, 0.0f), usable, virt ? 2.0f : 1.0f));
  imageStore(coarse, ivec3(cell, 5), vec4(ri, 1.0f));
  imageStore(coarse, ivec3(cell, 6), vec4(ri_v, 1.0f));
}
