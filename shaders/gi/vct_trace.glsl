// Cone tracing through dvct's four volumes (delta-voxel-cone-tracing.md Sec. 3.2; the math is
// shaders/shared/vct_math.h, unit-tested on the CPU): the light volume (every surface, the
// virtual objects included), the delta light volume (with the objects minus without), and one
// visibility volume each for the real scene and the virtual objects. Samples along the cone at
// footprints that touch (vct_next_distance) times `step_scale`, each read at the mip level of its
// footprint from every volume it needs (trilinear within a level), composited front to back
// until the cone is occluded, leaves the volume or reaches `max_distance`. Needs
// shared/vct_math.h included first.
//
// Two accumulations in one march (the same samples, the same footprints):
//   - "with" the objects: the light volume through both visibility volumes (what a virtual
//     pixel sees, and a real one once the objects are there);
//   - "without" them (VCT_WITHOUT): light volume minus delta volume (= the scene-only light
//     the paper subtracts) through the scene's visibility alone.
// A real pixel's change is with - without. The paper relights real pixels from the delta volume
// through both visibility volumes; that holds the objects' bounce and the light they block at
// its source (their shadow on the scene), but not the scene light they hide from the pixel (a
// real wall's bounce, or its reflection in a real mirror, behind the object): with - without
// holds all three and equals the paper's term where the objects hide nothing. A shadow cone
// (no VCT_LIGHT) reads the visibility volumes only: trans_with against trans_without is the
// objects' shadow where the scene does not already shadow (no double shadow, Sec. 3.2).

struct VctVolume {
  vec3 origin;            // the volumes' min corner (m)
  float voxel_size;       // m
  float cells;            // voxels per side (used)
  float texture_cells;    // voxels per side allocated: a cheaper level's volume is a corner of
                          // each mip level (gi/volume.h set_divisor), so texture coordinates
                          // divide by this
  float max_lod;          // the coarsest mip level holding data
  float occlusion_floor;  // vct_directional_occlusion's floor_fraction
  float step_scale;       // vct_step: the fraction of the touching-footprint step taken
};

struct VctResult {
  vec3 light_with;      // light gathered with the objects (rgb)
  float trans_with;     // the cone's transmittance through both visibility volumes
  vec3 light_without;   // the scene-only light through the scene's visibility (VCT_WITHOUT)
  float trans_without;  // the transmittance through the scene's visibility alone (VCT_WITHOUT)
};

const int VCT_LIGHT = 1;    // gather light (else: occlusion only, a shadow cone)
const int VCT_WITHOUT = 2;  // also the accumulation without the objects
// With VCT_LIGHT: the objects' own light volume (their ambient and emission,
// voxel_inject_surfaces.comp) adds to the light "with" them; "without" never holds it. Only the
// specular cone reads it: the diffuse cones' share of that light is the direct-light block's
// (its environment occlusion gives back the objects' ambient-lit surfaces).
const int VCT_OBJECT_LIGHT = 4;

VctResult vct_trace_cone(sampler3D light_volume, sampler3D delta_volume, sampler3D scene_visibility,
                         sampler3D object_visibility, sampler3D object_light, VctVolume v, vec3 origin, vec3 dir,
                         float aperture, float max_distance, int flags) {
  const bool want_light = (flags & VCT_LIGHT) != 0, want_without = (flags & VCT_WITHOUT) != 0;
  const bool want_object_light = want_light && (flags & VCT_OBJECT_LIGHT) != 0;
  const float ratio = vct_diameter_ratio(aperture);
  const float min_diameter = 0.5f;                        // voxels
  const vec3 start = (origin - v.origin) / v.voxel_size;  // voxel units
  const float limit = max_distance / v.voxel_size;
  VctResult r;
  r.light_with = vec3(0.0f);
  r.light_without = vec3(0.0f);
  r.trans_with = 1.0f;
  r.trans_without = 1.0f;
  // The march runs where the ray is inside the region: a cone from outside it (a real pixel
  // beyond it, a shadow cone towards a lamp) starts where it enters, with the footprint it has
  // there, and nothing is read after it leaves (the sampler would repeat the edge).
  const vec3 inv = 1.0f / (abs(dir) + 1e-12f) * sign(dir + 1e-30f);
  const vec3 t_a = (vec3(0.0f) - start) * inv, t_b = (vec3(v.cells) - start) * inv;
  const vec3 t_lo = min(t_a, t_b), t_hi = max(t_a, t_b);
  const float enter = max(max(t_lo.x, t_lo.y), t_lo.z), leave = min(min(t_hi.x, t_hi.y), t_hi.z);
  float d = max(1.0f, enter);
  const float end = min(limit, leave);
  for (int step = 0; step < 512 && d < end; ++step) {
    if (r.trans_with < 0.01f && (!want_without || r.trans_without < 0.01f)) break;
    const vec3 p = start + d * dir;
    const float next = vct_step(ratio, d, min_diameter, v.step_scale);
    const float lod = vct_lod(vct_diameter(ratio, d, min_diameter), v.max_lod);
    const vec3 uvw = p / v.texture_cells;
    const vec4 vis_s = textureLod(scene_visibility, uvw, lod);
    const vec4 vis_o = textureLod(object_visibility, uvw, lod);
    const float a_s = vct_opacity_for_step(vct_directional_occlusion(vis_s, dir, v.occlusion_floor, lod), v.step_scale);
    const float a_o = vct_opacity_for_step(vct_directional_occlusion(vis_o, dir, v.occlusion_floor, lod), v.step_scale);
    const float a_with = 1.0f - (1.0f - a_s) * (1.0f - a_o);
    if (want_light) {
      const vec3 light = textureLod(light_volume, uvw, lod).rgb;
      const vec3 light_with = want_object_light ? light + textureLod(object_light, uvw, lod).rgb : light;
      const vec4 both = vec4(vis_s.xyz + vis_o.xyz, min(vis_s.w + vis_o.w, 1.0f));
      const vec4 s = vct_sample(light_with, both, dir, v.occlusion_floor, lod);
      r.light_with += vct_light_for_step(s, v.step_scale) * r.trans_with;
      if (want_without) {
        const vec3 scene_light = light - textureLod(delta_volume, uvw, lod).rgb;
        const vec4 t = vct_sample(scene_light, vis_s, dir, v.occlusion_floor, lod);
        r.light_without += vct_light_for_step(t, v.step_scale) * r.trans_without;
      }
    }
    r.trans_with *= 1.0f - a_with;
    r.trans_without *= 1.0f - a_s;
    d = next;
  }
  return r;
}
