// The irradiance a dlpv volume gives a surface (dlpv/merge.comp, shading/direct_light.comp),
// from `volume`, which the including shader fills from its push constants; needs
// shared/lpv_math.h.
#ifndef MRGI_DLPV_VOLUME_LOOKUP_GLSL
#define MRGI_DLPV_VOLUME_LOOKUP_GLSL

struct VolumeConstants {
  vec4 grid;    // xyz: the volumes' min corner (m); w: cell size (m)
  vec4 extent;  // x: cells allocated per side; y: cells used; z: 1 = V^Delta present; w: 1 = V^rho
};
VolumeConstants volume;  // private copy of the push constants' (MRGI_UNIFORM_COPIES)

// Whether p lies in the used volume (a surface outside it gets no light from the volume).
bool volume_contains(vec3 p) {
  vec3 cellf = (p - volume.grid.xyz) / volume.grid.w;
  return all(greaterThanEqual(cellf, vec3(0.0f))) && all(lessThanEqual(cellf, vec3(volume.extent.y)));
}

// Irradiance from a volume's accumulated intensity at p for normal n, per channel; 0 outside.
vec3 volume_irradiance(sampler3D r, sampler3D g, sampler3D b, vec3 p, vec3 n) {
  vec3 cellf = (p - volume.grid.xyz) / volume.grid.w;  // in cells
  if (any(lessThan(cellf, vec3(0.0f))) || any(greaterThan(cellf, vec3(volume.extent.y)))) return vec3(0.0f);
  // The used corner of the allocation; clamped half a cell inside it so the trilinear filter
  // never reads a cell beyond the used size (stale: this level did not write it).
  vec3 uvw = clamp(cellf, vec3(0.5f), vec3(volume.extent.y - 0.5f)) / volume.extent.x;
  return vec3(lpv_irradiance(textureLod(r, uvw, 0.0f), n, volume.grid.w),
              lpv_irradiance(textureLod(g, uvw, 0.0f), n, volume.grid.w),
              lpv_irradiance(textureLod(b, uvw, 0.0f), n, volume.grid.w));
}

#endif  // MRGI_DLPV_VOLUME_LOOKUP_GLSL
