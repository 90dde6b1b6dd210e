// The splat step of the ISM passes (ism_splat_real.comp, ism_splat_virtual.comp): a point p
// (unit surface normal `normal`) that stands for `area` m^2 of surface, splatted into VPL
// `vpl`'s map as a square of texels sized to the solid angle it covers from the VPL (a
// directional VPL: the area it covers across the light) (the paper's "splats sized to fill", Sec. 4.3), each
// texel keeping the nearest distance (atomic min on the float's bits: non-negative floats order
// as their bits do). The including shader declares `vpls` (Vpl[]), `splat` (r32ui) and `params`.
#ifndef MRGI_ISM_SPLAT_GLSL
#define MRGI_ISM_SPLAT_GLSL

void ism_splat(int vpl, vec3 p, vec3 normal, float area) {
  Vpl v = vpls[vpl];
  int flags = int(v.position.w);
  if ((flags & MRGI_VPL_VALID) == 0) return;
  int side = params.tiles.y;
  ivec2 texel;
  float dist;
  int r;
  if ((flags & MRGI_VPL_DIRECTIONAL) != 0) {
    // Orthographic: the point covers its area projected across the light (x |cos| of its
    // normal to it: a floor under a low sun covers few texels, and a splat as wide as the point
    // facing the light would hide the floor beyond it) over a texel's (2 half_side / side)^2.
    texel = ism_ortho_texel(p, v.position.xyz, v.normal.xyz, v.normal.w, side, dist);
    if (texel.x < 0) return;
    float texel_side = 2.0f * v.normal.w / float(side);
    float texels = area * abs(dot(normal, v.normal.xyz)) / (texel_side * texel_side);
    r = clamp(int(sqrt(max(texels, 0.0f) / MRGI_PI) + 0.5f), 0, MRGI_ISM_MAX_SPLAT_RADIUS);
  } else {
    vec3 d = p - v.position.xyz;
    float dist2 = dot(d, d);
    if (!(dist2 > 1e-12f) || isinf(dist2)) return;
    dist = sqrt(dist2);
    vec3 w = d / dist;
    // Points (nearly) in the VPL's own tangent plane are left out: they lie on its own surface,
    // can only hide directions along that plane, where the VPL emits (cos) almost nothing, and
    // their splats, large for being so near, would hide the directions just above the plane: the
    // floor around a lit box, the box's foot seen from a floor VPL.
    if (dot(w, v.normal.xyz) < MRGI_ISM_MIN_ELEVATION_COS) return;
    vec2 uv = paraboloid_uv(w, v.normal.xyz);
    if (dot(uv, uv) > 1.0f) return;
    texel = clamp(ivec2(floor((uv * 0.5f + 0.5f) * float(side))), ivec2(0), ivec2(side - 1));
    float texels = area / dist2 / paraboloid_texel_solid_angle(uv, float(side));
    r = clamp(int(sqrt(max(texels, 0.0f) / MRGI_PI) + 0.5f), 0, MRGI_ISM_MAX_SPLAT_RADIUS);
  }
  ivec2 origin = ism_tile_origin(vpl, params.tiles.z, side);
  uint bits = floatBitsToUint(dist);
  for (int y = -r; y <= r; ++y)
    for (int x = -r; x <= r; ++x) {
      ivec2 q = texel + ivec2(x, y);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(side)))) continue;
      imageAtomicMin(splat, origin + q, bits);
    }
}

#endif
