// Adds flux (W, rgb) into the voxel of a light volume's sums holding `at` (gi/voxel_light.h):
// shared by the injections from reflective shadow maps (voxel_inject.comp) and from the virtual
// surfaces (voxel_inject_surfaces.comp). Needs GL_EXT_shader_atomic_float and an r32f
// imageBuffer `cells` (3 floats a cell). A point outside the volume adds nothing.
#ifndef MRGI_VOXEL_FLUX_GLSL
#define MRGI_VOXEL_FLUX_GLSL

void add_flux(vec3 at, vec3 flux, vec4 region, int n) {
  const ivec3 c = ivec3(floor((at - region.xyz) / region.w));
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(n)))) return;
  const int base = ((c.z * n + c.y) * n + c.x) * 3;
  for (int ch = 0; ch < 3; ++ch)
    if (flux[ch] != 0.0) imageAtomicAdd(cells, base + ch, flux[ch]);
}

#endif  // MRGI_VOXEL_FLUX_GLSL
