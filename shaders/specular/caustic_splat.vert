#version 460
// Caustic photons splatted as squares into the caustic buffer CBuf at the camera's internal
// resolution (caustics-DIR paper Sec. 5.2; Wyman and Davis 2006, quad sizes after Wyman 2008):
// a point sprite per photon that landed (photons.comp lists them), a square of `side` pixels
// around where it landed, each of its pixels given E = flux / (the square's area on the surface),
// so the buffer holds irradiance and the photons' energy is kept whatever the size. A point, not
// a six-vertex quad: lavapipe shades vertices on one thread, and six vertices a photon (each
// reading its photon and two neighbours) made this pass 6 ms of a 128^2 map. A point whose centre
// is outside the view is clipped whole (Vulkan's point clipping): a caustic loses at most half a
// square at the image's border.
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
#include "specular/photon.glsl"
layout(std430, set = 0, binding = 1) readonly buffer Photons { Photon photons[]; };
layout(std430, set = 0, binding = 4) readonly buffer PhotonList { uint photon_list[]; };  // photons.comp
layout(push_constant) uniform Splat { vec4 splat; };  // x smallest side (internal pixels), z largest
                                                     // (at most the device's largest point)
layout(location = 0) flat out vec4 out_irradiance;   // rgb W/m^2; w the photon's camera depth
layout(location = 1) flat out float out_real;        // 1: it landed on a real surface

void main() {
  int index = int(photon_list[gl_VertexIndex]);
  Photon ph = photons[index];
  gl_Position = vec4(2.0f, 2.0f, 2.0f, 1.0f);  // outside: dropped
  gl_PointSize = 1.0f;
  out_irradiance = vec4(0.0f);
  if (!(ph.position.w > 0.5f)) return;
  vec3 c = (frame.world_to_camera * vec4(ph.position.xyz, 1.0f)).xyz;
  if (!(c.z > 1e-3f)) return;
  vec3 to_camera = normalize(frame.camera_world.xyz - ph.position.xyz);
  float cos_view = max(abs(dot(normalize(ph.normal.xyz), to_camera)), 0.1f);
  float px_m = c.z / frame.internal_k.x;  // a pixel's side on a surface facing the camera
  // The square covers the photon's share of the surface: its footprint (photon_footprint.comp,
  // small where the object focuses the light, the caustic's sharp core; large where it spreads
  // it, whose few photons would otherwise be dots).
  float spacing = ph.albedo.w;
  float side = clamp(spacing / px_m, splat.x, splat.z);
  float area = side * side * px_m * px_m / cos_view;
  out_irradiance = vec4(ph.flux.rgb / area, c.z);
  out_real = ph.position.w < 1.5f ? 1.0f : 0.0f;
  gl_Position = frame.world_to_clip * vec4(ph.position.xyz, 1.0f);
  gl_PointSize = side;
}
