#version 460
// A lamp's photons splatted into its caustic receiver map (specular/caustic_receiver.glsl; the
// fast level's caustics): a point per photon that landed (photons.comp lists them) at the
// direction it landed in from the lamp, a square of texels sized by its footprint
// (shared/specular_math.h caustic_receiver_square), each texel given E = flux / (the square's
// area on the surface), so the map holds irradiance and the photons' energy whatever the size.
// Drawn once per photon trace, not per frame: the map is world-space, and the camera's pixels
// read it (caustic_receiver_irradiance).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "specular/caustic_receiver.glsl"
#include "specular/photon.glsl"

layout(std430, set = 0, binding = 1) readonly buffer Photons { Photon photons[]; };
layout(std430, set = 0, binding = 4) readonly buffer PhotonList { uint photon_list[]; };  // photons.comp
// The lamp (caustic_receiver.glsl: position.w the map's side) and, in sizes, x the smallest
// square side (texels), y the largest (at most the device's largest point).
layout(push_constant) uniform Receiver { CausticReceiverLamp lamp; vec4 sizes; };
layout(location = 0) flat out vec4 out_irradiance;  // rgb W/m^2; w the photon's distance from the lamp

void main() {
  Photon ph = photons[int(photon_list[gl_VertexIndex])];
  gl_Position = vec4(2.0f, 2.0f, 2.0f, 1.0f);  // outside: dropped
  gl_PointSize = 1.0f;
  out_irradiance = vec4(0.0f);
  if (!(ph.position.w > 0.5f)) return;
  vec3 d = ph.position.xyz - lamp.position.xyz;
  float r = length(d);
  if (!(r > 1e-4f)) return;
  vec3 local = caustic_receiver_direction(lamp, d / r);
  float size = lamp.position.w;
  float texel_sr = oct_texel_solid_angle(local, size);
  float cos_l = abs(dot(normalize(ph.normal.xyz), d / r));
  vec2 square = caustic_receiver_square(ph.albedo.w, r, cos_l, texel_sr, sizes.x, sizes.y);
  out_irradiance = vec4(ph.flux.rgb / square.y, r);
  // The map's texel (e * 0.5 + 0.5) * size is the viewport's for clip xy = e (Vulkan: y = -1 is
  // the first row, as caustic_receiver_irradiance reads it).
  gl_Position = vec4(oct_encode(local), 0.5f, 1.0f);
  gl_PointSize = square.x;
}
