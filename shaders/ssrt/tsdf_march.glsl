// Ray marching through the ssrt TSDF volume (KinectFusion's surface prediction, Newcombe et al.
// 2011 Sec. 3.4): shared by ssrt_tsdf_raycast (perspective view) and ssrt_tsdf_aux (orthographic
// layers). The including shader declares, before including this file:
//   layout(std140, ...) uniform VolumeUbo { SsrtVolumeParams volume; };
//   layout(set = 0, binding = N, r32ui) readonly uniform uimageBuffer voxels;
#ifndef MRGI_SSRT_TSDF_MARCH_GLSL
#define MRGI_SSRT_TSDF_MARCH_GLSL

// Trilinear TSDF at world point p. Valid only when all eight voxels around p were observed:
// interpolating across never-observed voxels (weight 0, value 0) would invent zero crossings
// on the border of what the camera has seen.
bool tsdf_sample(vec3 p, out float value) {
  int r = volume.grid.x;
  vec3 g = (p - volume.origin.xyz) / volume.origin.w - 0.5f;
  value = 1.0f;
  if (any(lessThan(g, vec3(0.0f))) || any(greaterThanEqual(g, vec3(float(r - 1))))) return false;
  ivec3 b = ivec3(floor(g));
  vec3 f = g - vec3(b);
  int base = b.x + r * (b.y + r * b.z);
  int row = r, slice = r * r;
  vec2 c000 = unpackHalf2x16(imageLoad(voxels, base).x);
  vec2 c100 = unpackHalf2x16(imageLoad(voxels, base + 1).x);
  vec2 c010 = unpackHalf2x16(imageLoad(voxels, base + row).x);
  vec2 c110 = unpackHalf2x16(imageLoad(voxels, base + row + 1).x);
  vec2 c001 = unpackHalf2x16(imageLoad(voxels, base + slice).x);
  vec2 c101 = unpackHalf2x16(imageLoad(voxels, base + slice + 1).x);
  vec2 c011 = unpackHalf2x16(imageLoad(voxels, base + slice + row).x);
  vec2 c111 = unpackHalf2x16(imageLoad(voxels, base + slice + row + 1).x);
  float wmin = min(min(min(c000.y, c100.y), min(c010.y, c110.y)),
                   min(min(c001.y, c101.y), min(c011.y, c111.y)));
  if (!(wmin > 0.0f)) return false;
  float x00 = mix(c000.x, c100.x, f.x), x10 = mix(c010.x, c110.x, f.x);
  float x01 = mix(c001.x, c101.x, f.x), x11 = mix(c011.x, c111.x, f.x);
  value = mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
  return true;
}

// World unit normal at p from the TSDF's central differences (one voxel each side); points
// out of the surface (towards positive TSDF). False where a neighbour sample is not valid.
bool tsdf_normal(vec3 p, out vec3 n) {
  float h = volume.origin.w;
  float xp, xm, yp, ym, zp, zm;
  n = vec3(0.0f);
  if (!tsdf_sample(p + vec3(h, 0, 0), xp) || !tsdf_sample(p - vec3(h, 0, 0), xm) ||
      !tsdf_sample(p + vec3(0, h, 0), yp) || !tsdf_sample(p - vec3(0, h, 0), ym) ||
      !tsdf_sample(p + vec3(0, 0, h), zp) || !tsdf_sample(p - vec3(0, 0, h), zm))
    return false;
  vec3 g = vec3(xp - xm, yp - ym, zp - zm);
  float len = length(g);
  if (!(len > 1e-6f)) return false;
  n = g / len;
  return true;
}

// The ray o + t d (d unit) clipped to where tsdf_sample can be valid: [t0, t1], t0 >= t_min.
bool tsdf_clip(vec3 o, vec3 d, float t_min, out float t0, out float t1) {
  float h = volume.origin.w;
  vec3 lo = volume.origin.xyz + vec3(0.5f * h);
  vec3 hi = volume.origin.xyz + vec3((float(volume.grid.x) - 0.5f) * h - 1e-4f * h);
  // Axis-parallel rays (the aux layers' rays often are): a tiny component instead of 0 keeps
  // the slab test finite (0 * inf would be NaN for a ray starting on a slab plane).
  vec3 safe = mix(d, mix(vec3(-1e-9f), vec3(1e-9f), greaterThanEqual(d, vec3(0.0f))),
                  lessThan(abs(d), vec3(1e-9f)));
  vec3 inv = 1.0f / safe;
  vec3 ta = (lo - o) * inv, tb = (hi - o) * inv;
  vec3 tn = min(ta, tb), tf = max(ta, tb);
  t0 = max(max(max(tn.x, tn.y), tn.z), t_min);
  t1 = min(min(tf.x, tf.y), tf.z);
  return t0 < t1;
}

// First front-facing zero crossing (positive -> negative, both samples valid) of the TSDF along
// o + t d for t >= t_min. Steps by the TSDF distance (at least one voxel, at most 0.9 mu: any
// step shorter than mu lands inside the negative band of a surface it crosses, whose thickness
// along a ray is mu / cos >= mu), then places the crossing by linear interpolation of the two
// samples around it. Returns t, or -1 when the ray leaves the cube without a crossing.
float tsdf_march(vec3 o, vec3 d, float t_min) {
  float t0, t1;
  if (!tsdf_clip(o, d, t_min, t0, t1)) return -1.0f;
  float h = volume.origin.w, mu = volume.tsdf.x;
  float max_step = max(h, 0.9f * mu);
  float t = t0, t_prev = t0, f_prev = 0.0f;
  bool prev_valid = false;
  // Bounded: every step is at least one voxel.
  int max_steps = int(ceil((t1 - t0) / h)) + 2;
  for (int i = 0; i < max_steps && t <= t1; ++i) {
    float f;
    bool valid = tsdf_sample(o + t * d, f);
    if (valid && prev_valid && f_prev > 0.0f && f <= 0.0f)
      return t_prev + (t - t_prev) * f_prev / (f_prev - f);
    float step = valid ? clamp(f * mu, h, max_step) : max_step;
    t_prev = t;
    f_prev = f;
    prev_valid = valid;
    t += step;
  }
  return -1.0f;
}

#endif  // MRGI_SSRT_TSDF_MARCH_GLSL
