// Shared by recon/warp_depth.comp and recon/depth_to_positions.comp: how a warped depth and its
// weight are packed into one 32-bit word so that the forward warp resolves overlaps with a
// single imageAtomicMin (nearest surface wins, like the DIR paper's z-test).
#ifndef MRGI_RECON_DEPTH_FILTER_GLSL
#define MRGI_RECON_DEPTH_FILTER_GLSL

// Depth in units of 2^-20 m (about 1 micrometre) in the top 24 bits: depths up to 16 m; the
// weight (whole frames, <= 255) in the low 8 bits.
#define MRGI_WARP_EMPTY 0xffffffffu
#define MRGI_WARP_DEPTH_UNITS 1048576.0f
#define MRGI_WARP_MAX_DEPTH 15.99f

uint pack_warped(float z, float weight) {
  uint q = min(uint(z * MRGI_WARP_DEPTH_UNITS + 0.5f), 0xfffffeu);
  return (q << 8) | min(uint(weight + 0.5f), 255u);
}
// (depth metres, weight frames); (0, 0) for an empty pixel.
vec2 unpack_warped(uint packed) {
  if (packed == MRGI_WARP_EMPTY) return vec2(0.0f);
  return vec2(float(packed >> 8) / MRGI_WARP_DEPTH_UNITS, float(packed & 0xffu));
}

#endif
