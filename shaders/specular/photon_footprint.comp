#version 460
// Each landed photon's footprint (photon.glsl albedo.w): the distance to where the neighbouring
// photons of its kind landed (a ray differential: small where the object focuses the light, the
// caustic's sharp core; large where it spreads it). World-space, so computed once per trace
// (photons.comp), not per frame in the splat's vertex shader, whose neighbour reads lavapipe
// runs on one thread.
#extension GL_GOOGLE_include_directive : require
#include "specular/photon.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = 0) buffer Photons { Photon photons[]; };
layout(push_constant) uniform Map { ivec4 map; };  // x the photon map's side (texels)

// Where the photon of kind `kind` `step` texels from t landed, or `own`.
vec3 neighbour(ivec2 t, int kind, ivec2 step, vec3 own) {
  int size = map.x;
  ivec2 q = t + step;
  if (any(greaterThanEqual(q, ivec2(size)))) return own;
  vec4 p = photons[2 * (q.y * size + q.x) + kind].position;
  return p.w > 0.5f ? p.xyz : own;
}

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(map.x)))) return;
  for (int kind = 0; kind < 2; ++kind) {
    int i = 2 * (t.y * map.x + t.x) + kind;
    vec4 p = photons[i].position;
    if (!(p.w > 0.5f)) continue;
    int stride = max(int(photons[i].normal.w + 0.5f), 1);
    float spacing = max(distance(neighbour(t, kind, ivec2(stride, 0), p.xyz), p.xyz),
                        distance(neighbour(t, kind, ivec2(0, stride), p.xyz), p.xyz));
    photons[i].albedo.w = spacing;
  }
}
