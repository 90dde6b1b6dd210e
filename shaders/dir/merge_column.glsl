// dir: the geometry-aware merge's second half (merge_rows.comp has the first), shared by
// merge_columns.comp and temporal.comp (which merges its own texel's column instead of reading a
// merged image: one pass and one image round trip fewer a frame). The includer declares the
// row-merged image as `rows` (rgba32ui, readonly) and includes gi/indirect_pack.glsl first.
#ifndef MRGI_DIR_MERGE_COLUMN_GLSL
#define MRGI_DIR_MERGE_COLUMN_GLSL

// The average of the row-merged light of the `side` texels of pixel's column around it
// (offsets -side/2 .. side/2 - 1: every row residue of the interleaving once) that lie on its
// own surface (same_surface), packed with its key; 0 where the pixel has no surface.
uvec4 merge_column(ivec2 pixel, ivec2 extent, int side) {
  uvec4 centre = imageLoad(rows, pixel);
  if (centre.w == 0u) return uvec4(0u);  // no surface: nothing shaded here
  vec3 rv = vec3(0.0f), r = vec3(0.0f);
  float weight = 0.0f;
  side = max(side, 1);
  int lo = -(side / 2);
  for (int y = lo; y < lo + side; ++y) {
    ivec2 q = ivec2(pixel.x, clamp(pixel.y + y, 0, extent.y - 1));
    uvec4 t = y == 0 ? centre : imageLoad(rows, q);
    if (!same_surface(centre.w, t.w)) continue;
    rv += unpack_indirect_rv(t);
    r += unpack_indirect_r(t);
    weight += 1.0f;
  }
  float k = 1.0f / max(weight, 1.0f);
  return pack_indirect(rv * k, r * k, vec3(0.0f), 0.0f, false) & uvec4(~0u, ~0u, ~0u, 0u) | uvec4(0u, 0u, 0u, centre.w);
}

#endif
