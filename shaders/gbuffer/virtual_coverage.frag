#version 460
// The virtual objects' coverage at the output resolution (recon::VirtualGBuffer::record_coverage):
// 1 where a virtual object is seen, 0 elsewhere (the clear), for a frame whose G-buffer is at a
// lower internal resolution, so the real/virtual mask and the silhouettes compose shows come at
// the output's pixels whatever the internal scale. The occlusion test by the real geometry is the
// G-buffer's own (hidden_by_real.glsl), on the output's pixel rays. No depth attachment: any
// object covering a pixel covers it, whichever is in front.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"
#include "common/frame_constants.glsl"
#include "gbuffer/hidden_by_real.glsl"

layout(set = 0, binding = 2) uniform sampler2D real_position;  // xyz world, w depth
layout(set = 0, binding = 4) uniform sampler2D real_normal;    // xyz world (coarse texels)
// virtual_coverage.vert's outputs, all this test reads.
layout(location = 3) in float in_view_z;
layout(location = 7) flat in vec4 in_k;         // output intrinsics
layout(location = 8) flat in vec4 in_camera;    // w behind-real tolerance
layout(location = 9) flat in mat3x4 in_to_camera;
layout(location = 13) flat in vec2 in_real_scale;  // real texels per pixel (x, y)
layout(location = 0) out float out_coverage;

void main() {
  if (hidden_by_real(real_position, real_normal, ivec2(gl_FragCoord.xy), in_k, in_to_camera, in_view_z,
                     in_real_scale, in_camera.w))
    discard;
  out_coverage = 1.0f;
}
