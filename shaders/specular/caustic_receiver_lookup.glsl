// caustic_receiver_irradiance: the fast level's caustics on a surface point, read from the
// receiver maps (caustic_receiver.glsl says what they hold).
#ifndef MRGI_SPECULAR_CAUSTIC_RECEIVER_LOOKUP_GLSL
#define MRGI_SPECULAR_CAUSTIC_RECEIVER_LOOKUP_GLSL

// The caustic irradiance (W/m^2) on the surface point x, seen by a pixel sqrt(footprint_sq)
// metres wide there, from every lamp's map: the nearest texel of the level whose texels are about as wide
// (caustic_receiver_mip.comp's halvings: the caustic averaged over the pixel, not point-sampled
// where pixels are wider than mip 0's texels), where its photons landed at x's distance from the
// lamp (caustic_same_surface, the camera's splat's rule), so a caustic on the table does
// not light the sphere above it that the lamp sees in the same direction. Nearest, not bilinear:
// the level's texels are the pixel's size, and each of three more reads cost 0.25 ms of
// shade_direct's 6.1 at dir fast on glass_mirror (lavapipe, 320 x 240).
// The including shader declares `caustic_receivers` (rgba32f image2D: rgb irradiance, a
// luminance x distance from the lamp, summed over the photons) and `receiver_set`
// (CausticReceivers) before including this, and includes shared/mrgi_shared.h,
// shared/specular_math.h and specular/caustic_receiver.glsl first.
// The first lamp's map and the count, copied on main's first line (cache_caustic_receivers:
// lavapipe loads a buffer value once a SIMD batch only there, lane by lane anywhere else;
// MRGI_UNIFORM_COPIES, common/frame_constants.glsl).
CausticReceiverLamp receiver_lamp0;
int receiver_count;
void cache_caustic_receivers() {
  receiver_count = min(receiver_set.count.x, MRGI_CAUSTIC_RECEIVER_LAMPS);
  receiver_lamp0 = receiver_set.lamps[0];
}

vec3 caustic_receiver_from(CausticReceiverLamp L, vec3 x, float footprint_sq) {
  vec3 d = x - L.position.xyz;
  float r = length(d);
  if (!(r > 1e-4f)) return vec3(0.0f);
  int size = int(L.position.w);
  vec3 local = caustic_receiver_direction(L, d / r);
  // The level nearest in log2 of footprint / texel width, by squared comparisons (no sqrt or
  // log2 a pixel): level k's texels are 2^k of mip 0's, r sqrt(texel sr) wide.
  float texel_sq = r * r * oct_texel_solid_angle(local, float(size));
  int k = int(footprint_sq > 2.0f * texel_sq) + int(footprint_sq > 8.0f * texel_sq) +
          int(footprint_sq > 32.0f * texel_sq) + int(footprint_sq > 128.0f * texel_sq);
  k = min(k, L.atlas.z - 1);
  int side = size >> k;
  vec2 uv = (oct_encode(local) * 0.5f + 0.5f) * float(side);
  ivec2 t = caustic_receiver_origin(L.atlas.xy, size, k) + clamp(ivec2(uv), ivec2(0), ivec2(side - 1));
  vec4 v = imageLoad(caustic_receivers, t);
  float lum = luminance(v.rgb);
  return lum > 0.0f && caustic_same_surface(r, v.a / lum) ? max(v.rgb, vec3(0.0f)) : vec3(0.0f);
}

vec3 caustic_receiver_irradiance(vec3 x, float footprint_sq) {
  vec3 sum = receiver_count > 0 ? caustic_receiver_from(receiver_lamp0, x, footprint_sq) : vec3(0.0f);
  for (int i = 1; i < receiver_count; ++i) sum += caustic_receiver_from(receiver_set.lamps[i], x, footprint_sq);
  return finite3(sum);
}

#endif  // MRGI_SPECULAR_CAUSTIC_RECEIVER_LOOKUP_GLSL
