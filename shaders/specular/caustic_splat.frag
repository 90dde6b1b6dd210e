#version 460
// A caustic photon's quad (caustic_splat.vert) on the pixels whose visible surface it landed on:
// the G-buffers' depth there within a tolerance of the photon's (a photon behind a nearer surface
// at this pixel lights nothing here). Added into CBuf (additive blending): rgb irradiance, a the
// number of photons.
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;     // w camera depth
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D virtual_position;  // w > 0.5 virtual
layout(location = 0) flat in vec4 in_irradiance;
layout(location = 0) out vec4 out_caustic;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 v = imageLoad(virtual_position, pixel);
  float depth = v.w > 0.5f ? (frame.world_to_camera * vec4(v.xyz, 1.0f)).z : imageLoad(real_position, pixel).w;
  if (!(depth > 0.0f) || abs(depth - in_irradiance.w) > 0.03f * depth + 0.01f) discard;
  out_caustic = vec4(in_irradiance.rgb, 1.0f);
}
