// Cone tracing through a voxel light volume and its visibility volume (dvct; the math is
// shaders/shared/vct_math.h, unit-tested on the CPU): samples along the cone at footprints that
// touch (vct_next_distance), each read at the mip level of its footprint from both volumes
// (trilinear within a level), composited front to back until the cone is occluded, leaves the
// volume or reaches `max_distance`. Needs shared/vct_math.h included first.

struct VctVolume {
  vec3 origin;       // the volumes' min corner (m)
  float voxel_size;  // m
  float cells;       // voxels per side (used)
  float max_lod;     // the coarsest mip level holding data
  float occlusion_floor;  // vct_directional_occlusion's floor_fraction
};

// Light (rgb) and occlusion (a) a cone gathers. `origin` (m) should already sit a voxel off the
// surface it starts from (the caller knows the normal); `aperture` the full aperture (radians);
// `max_distance` metres.
vec4 vct_trace(sampler3D light_volume, sampler3D visibility_volume, VctVolume v, vec3 origin, vec3 dir,
               float aperture, float max_distance) {
  const float ratio = vct_diameter_ratio(aperture);
  const float min_diameter = 0.5;                  // voxels
  const vec3 start = (origin - v.origin) / v.voxel_size;  // voxel units
  const float limit = max_distance / v.voxel_size;
  vec4 acc = vec4(0.0);
  float d = 1.0;
  bool entered = false;  // a cone from outside the region (a real pixel beyond it) may enter it
  for (int step = 0; step < 256 && d < limit && acc.w < 0.99; ++step) {
    const vec3 p = start + d * dir;
    const bool inside = all(greaterThanEqual(p, vec3(0.0))) && all(lessThanEqual(p, vec3(v.cells)));
    if (!inside) {
      if (entered) break;  // left it: nothing more to gather (the sampler would repeat the edge)
      d = vct_next_distance(ratio, d, min_diameter);
      continue;
    }
    entered = true;
    const float diameter = vct_diameter(ratio, d, min_diameter);
    const float lod = vct_lod(diameter, v.max_lod);
    const vec3 uvw = p / v.cells;
    const vec3 light = textureLod(light_volume, uvw, lod).rgb;
    const vec4 visibility = textureLod(visibility_volume, uvw, lod);
    const vec4 s = vct_sample(light, visibility, dir, v.occlusion_floor, lod);
    acc = vct_accumulate(acc, vec3(s.x, s.y, s.z), s.w);
    d = vct_next_distance(ratio, d, min_diameter);
  }
  return acc;
}
