// Surface voxelisation by sampling (gi/voxelize.h), shared by voxelize_mesh.comp and
// voxelize_depth.comp: a triangle is cut into k x k similar sub-triangles, k chosen so their
// edges are at most half a voxel, and each sub-triangle's centroid adds its area-weighted normal
// and its area into the voxel holding it. Every voxel a triangle crosses by more than a quarter
// voxel receives a sample; the resolve turns the sums into the mean normal and the occupancy.
// Why sampling and not rasterisation with a dominant-axis projection (the usual VCT voxeliser):
// one compute pass for meshes and the reconstruction's grid alike, no geometry shader, and the
// cost follows the surface area inside the region (samples outside it are dropped).
// Needs: GL_EXT_shader_atomic_float, an r32f imageBuffer `cells` (4 floats a cell: normal x
// area xyz, area; area in voxel^2), and the push block's `region` and `cells_per_side`.
// A shader that splats something else per sample (voxel_inject_surfaces.comp: a material's
// light) defines MRGI_SPLAT_VISIT(world, bary, g, sub_area) before including this: `bary` the
// sample's weights of p1 and p2, `g` the oriented unit face normal, `sub_area` in voxel^2; such a
// shader drops degenerate triangles (nothing to light).

// Sub-triangles per edge at most: a triangle longer than kMaxSplit / 2 voxels is sampled more
// sparsely than half a voxel (holes between samples possible); at a 64^3 volume that is a
// triangle longer than the volume, which only proxies (tables, walls) are, and those cross the
// region as a plane the samples still cover at 2 voxels' spacing or less.
const int kMaxSplit = 128;

#ifndef MRGI_SPLAT_VISIT
void splat_sample(vec3 world, vec3 normal_area, float area, vec4 region, int n) {
  const ivec3 c = ivec3(floor((world - region.xyz) / region.w));
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(n)))) return;
  const int base = ((c.z * n + c.y) * n + c.x) * 4;
  imageAtomicAdd(cells, base + 0, normal_area.x);
  imageAtomicAdd(cells, base + 1, normal_area.y);
  imageAtomicAdd(cells, base + 2, normal_area.z);
  imageAtomicAdd(cells, base + 3, area);
}

#define MRGI_SPLAT_VISIT(world, bary, g, sub_area) splat_sample(world, g * sub_area, sub_area, region, n)
#define MRGI_SPLAT_DEGENERATE(p0) splat_sample(p0, vec3(0.0), 1e-6, region, n)
#else
#define MRGI_SPLAT_DEGENERATE(p0)
#endif

// `oriented`: a normal on the triangle's front side (the geometric normal is turned to agree).
void splat_triangle(vec3 p0, vec3 p1, vec3 p2, vec3 oriented, vec4 region, int n) {
  const vec3 e1 = (p1 - p0) / region.w, e2 = (p2 - p0) / region.w;  // voxels
  vec3 g = cross(e1, e2);
  const float twice_area = length(g);
  if (!(twice_area > 0.0)) {
    // Degenerate (a line or a point): its vertices still mark their voxels as occupied.
    MRGI_SPLAT_DEGENERATE(p0);
    return;
  }
  g /= twice_area;
  if (dot(g, oriented) < 0.0) g = -g;
  // Quick reject: the triangle's box outside the region.
  const vec3 lo = min(p0, min(p1, p2)), hi = max(p0, max(p1, p2));
  const vec3 region_hi = region.xyz + region.w * float(n);
  if (any(greaterThan(lo, region_hi)) || any(lessThan(hi, region.xyz))) return;
  const float longest = max(length(e1), max(length(e2), length(e2 - e1)));
  const int k = clamp(int(ceil(2.0 * longest)), 1, kMaxSplit);
  const float sub_area = 0.5 * twice_area / float(k * k);
  const vec3 a = (p1 - p0) / float(k), b = (p2 - p0) / float(k);
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k - i; ++j) {
      // The sub-triangle (i, j), (i + 1, j), (i, j + 1) and, but on the last diagonal, the
      // flipped one (i + 1, j), (i + 1, j + 1), (i, j + 1): their centroids.
      const vec3 base = p0 + float(i) * a + float(j) * b;
      MRGI_SPLAT_VISIT(base + (a + b) / 3.0, (vec2(i, j) + 1.0 / 3.0) / float(k), g, sub_area);
      if (j < k - i - 1) MRGI_SPLAT_VISIT(base + 2.0 * (a + b) / 3.0, (vec2(i, j) + 2.0 / 3.0) / float(k), g, sub_area);
    }
  }
}
