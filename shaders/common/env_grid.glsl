// The light stage's environment grid as the shaders read it (light/env_sampler.h: world-space
// equirectangular radiance, width w cells, height w / 2; u = 0.5 + atan(x, -z) / 2 pi, v =
// acos(y) / pi), and a pyramid of it for cones wider than a cell (level l: w >> l cells wide,
// each cell the solid-angle-weighted mean of the 2 x 2 below it, stored after level l - 1).
// The including shader declares `vec4 env_cells[]` (a storage buffer, rgb radiance).
#ifndef MRGI_ENV_GRID_GLSL
#define MRGI_ENV_GRID_GLSL

// Cell (x, y) of the level `w` cells wide starting at `first`: wraps around in longitude and
// clamps at the poles.
vec3 env_grid_cell(int x, int y, int w, int first) {
  x = x - w * int(floor(float(x) / float(w)));
  y = clamp(y, 0, w / 2 - 1);
  return env_cells[first + y * w + x].rgb;
}

// The radiance towards unit d, bilinear between the cell centres of that level.
vec3 env_grid_bilinear(vec3 d, int w, int first) {
  const vec2 uv = vec2(0.5f + atan(d.x, -d.z) / (2.0f * MRGI_PI), acos(clamp(d.y, -1.0f, 1.0f)) / MRGI_PI);
  const vec2 c = uv * vec2(float(w), float(w / 2)) - 0.5f;
  const ivec2 c0 = ivec2(floor(c));
  const vec2 f = c - vec2(c0);
  return mix(mix(env_grid_cell(c0.x, c0.y, w, first), env_grid_cell(c0.x + 1, c0.y, w, first), f.x),
             mix(env_grid_cell(c0.x, c0.y + 1, w, first), env_grid_cell(c0.x + 1, c0.y + 1, w, first), f.x), f.y);
}

// The mean radiance over a cone of `half_angle` (radians) around unit d: the pyramid level whose
// cells span the cone's width, blended with the next (level 0 `w0` cells wide, `levels` levels).
vec3 env_grid_cone(vec3 d, float half_angle, int w0, int levels) {
  const float cell = 2.0f * MRGI_PI / float(w0);  // level 0's cell width at the equator (radians)
  const float level = clamp(log2(max(2.0f * half_angle / cell, 1.0f)), 0.0f, float(levels - 1));
  const int l0 = int(floor(level)), l1 = min(l0 + 1, levels - 1);
  int first0 = 0;
  for (int l = 0; l < l0; ++l) first0 += (w0 >> l) * ((w0 >> l) / 2);
  const int first1 = l1 == l0 ? first0 : first0 + (w0 >> l0) * ((w0 >> l0) / 2);
  return mix(env_grid_bilinear(d, w0 >> l0, first0), env_grid_bilinear(d, w0 >> l1, first1), level - float(l0));
}

#endif  // MRGI_ENV_GRID_GLSL
