#version 460
// A caustic photon's quad (caustic_splat.vert) on the pixels whose surface it landed on: a
// photon on a real surface where the real G-buffer's depth is within a tolerance of its own and
// no diffuse virtual object covers the pixel (under a mirror or glass it stays: what they show
// reads it, trace.comp caustic_at), one on a virtual surface where the virtual G-buffer's is.
// Added into CBuf (additive blending): rgb irradiance, a the number of photons.
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;     // w camera depth
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;  // w > 0.5 virtual
layout(location = 0) flat in vec4 in_irradiance;
layout(location = 1) flat in float in_real;
layout(location = 0) out vec4 out_caustic;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 v = imageLoad(virtual_position, pixel);
  bool diffuse_virtual = v.w > 0.5f && v.w < 1.5f;
  if (in_real > 0.5f && diffuse_virtual) discard;
  if (in_real < 0.5f && !(v.w > 0.5f)) discard;
  float depth = in_real > 0.5f ? imageLoad(real_position, pixel).w : (frame.world_to_camera * vec4(v.xyz, 1.0f)).z;
  if (!(depth > 0.0f) || abs(depth - in_irradiance.w) > 0.03f * depth + 0.01f) discard;
  out_caustic = vec4(in_irradiance.rgb, 1.0f);
}
