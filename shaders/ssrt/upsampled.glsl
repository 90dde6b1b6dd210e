// The Gauss-filtered coarse shading that ssrt_shade interpolates (fast levels), one RGBA32UI
// texel per cell in half precision, so each of the bicubic's 16 taps is one fetch instead of
// three RGBA32F ones (on lavapipe the fetches were most of the shade pass):
//   x  R_d, R'_d          y  R_i.rg          z  R_i.b, R'_i.r          w  R'_i.gb
// R_d, R'_d >= 0, so their sign bits carry the kind of surface: R'_d's set = a surface, R_d's set
// = a virtual one (kind 0 none, 1 real, 2 virtual as coarse layer 4 w). Equal R_d and R'_d stay
// equal after rounding, so a pixel nothing virtual affects still composes to the camera colour.
#ifndef MRGI_SSRT_UPSAMPLED_GLSL
#define MRGI_SSRT_UPSAMPLED_GLSL

uvec4 ssrt_pack_upsampled(float rd, float rd_v, vec3 ri, vec3 ri_v, float kind) {
  uint x = packHalf2x16(vec2(abs(rd), abs(rd_v)));
  x |= kind > 1.5f ? 0x00008000u : 0u;
  x |= kind > 0.5f ? 0x80000000u : 0u;
  return uvec4(x, packHalf2x16(ri.rg), packHalf2x16(vec2(ri.b, ri_v.r)), packHalf2x16(ri_v.gb));
}

// kind 0 none, 1 real, 2 virtual.
void ssrt_unpack_upsampled(uvec4 p, out float rd, out float rd_v, out vec3 ri, out vec3 ri_v,
                           out float kind) {
  vec2 d = unpackHalf2x16(p.x & 0x7fff7fffu);
  rd = d.x;
  rd_v = d.y;
  vec2 a = unpackHalf2x16(p.y), b = unpackHalf2x16(p.z), c = unpackHalf2x16(p.w);
  ri = vec3(a, b.x);
  ri_v = vec3(b.y, c);
  kind = (p.x & 0x80000000u) != 0u ? ((p.x & 0x00008000u) != 0u ? 2.0f : 1.0f) : 0.0f;
}

#endif  // MRGI_SSRT_UPSAMPLED_GLSL
