#version 460
// The caustics of the spot lamps through mirrors and glass (caustics-DIR paper eq. 12-14) added
// to the pixels that show a diffuse surface: L_rv += albedo / pi x E_caustic. L_r never gets
// them: the object the light went through is virtual (eq. 14's r(p) is false). A real surface
// takes the camera's albedo estimate (the reconstruction's), a virtual one its diffuse base
// colour; mirrors and glass show the caustics they see through their hits (trace.comp).
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D caustics;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_albedo;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_albedo;
layout(set = 0, binding = 6, rgba16f) uniform image2D lit_rv;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, frame.internal_output_size.xy))) return;
  vec4 e = imageLoad(caustics, pixel);
  if (!(e.a > 0.0f)) return;
  vec4 v = imageLoad(virtual_position, pixel);
  if (v.w > 1.5f) return;  // a mirror or glass pixel: its hits took their caustics (the real
                           // surface's under it are read through it, trace.comp)
  vec3 albedo;
  if (v.w > 0.5f) {
    vec4 a = imageLoad(virtual_albedo, pixel);
    albedo = a.rgb * (1.0f - a.a);
  } else {
    if (!(imageLoad(real_position, pixel).w > 0.0f)) return;
    albedo = imageLoad(real_albedo, pixel).rgb;
  }
  vec3 add = albedo * max(e.rgb, vec3(0.0f)) * (1.0f / 3.14159265f);
  vec4 l = imageLoad(lit_rv, pixel);
  imageStore(lit_rv, pixel, vec4(min(l.rgb + add, vec3(60000.0f)), l.a));
}
