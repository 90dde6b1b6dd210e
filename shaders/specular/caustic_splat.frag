#version 460
// A caustic photon's square (caustic_splat.vert) on the pixels whose surface it landed on: a
// photon on a real surface where the real G-buffer's depth is within a tolerance of its own and
// no diffuse virtual object covers the pixel (under a mirror or glass it stays: what they show
// reads it, trace.comp caustic_at), one on a virtual surface where the virtual G-buffer's is.
// Added (additive blending) into
//   CBuf    rgb irradiance (W/m^2), a the number of photons;
//   lit_rv  albedo / pi x the irradiance on the diffuse pixels (caustics-DIR paper eq. 12-14;
//           never L_r: the object the light went through is virtual, eq. 14's r(p) is false).
//           A real surface takes the camera's albedo estimate (the reconstruction's), a virtual
//           one its diffuse base colour; mirror and glass pixels get nothing here (the trace
//           writes them after this pass, from the caustics on what they show).
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "shared/specular_math.h"
#include "common/frame_constants.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;     // w camera depth
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;  // w > 0.5 virtual
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 6, rgba16f) readonly uniform image2D virtual_albedo;    // a metallic
layout(location = 0) flat in vec4 in_irradiance;
layout(location = 1) flat in float in_real;
layout(location = 0) out vec4 out_caustic;
layout(location = 1) out vec4 out_lit_rv;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 v = imageLoad(virtual_position, pixel);
  bool diffuse_virtual = v.w > 0.5f && v.w < 1.5f;
  if (in_real > 0.5f && diffuse_virtual) discard;
  if (in_real < 0.5f && !(v.w > 0.5f)) discard;
  float depth = in_real > 0.5f ? imageLoad(real_position, pixel).w : (frame.world_to_camera * vec4(v.xyz, 1.0f)).z;
  if (!(depth > 0.0f) || !caustic_same_surface(depth, in_irradiance.w)) discard;
  vec3 e = finite3(max(in_irradiance.rgb, vec3(0.0f)));
  out_caustic = vec4(e, 1.0f);
  vec3 albedo = vec3(0.0f);  // a mirror or glass pixel
  if (diffuse_virtual) {
    vec4 a = imageLoad(virtual_albedo, pixel);
    albedo = a.rgb * (1.0f - a.a);
  } else if (!(v.w > 0.5f)) {
    albedo = imageLoad(real_albedo, pixel).rgb;
  }
  out_lit_rv = vec4(albedo * e * (1.0f / MRGI_PI), 0.0f);
}
