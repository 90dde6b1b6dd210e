#version 460
// caustic_receiver.vert's square: its irradiance, and the irradiance's luminance times the
// photon's distance from the lamp (the reader divides the sums to get the texel's mean distance
// for its same-surface test), added (additive blending) into the lamp's receiver map.
#extension GL_GOOGLE_include_directive : require
#include "shared/mrgi_shared.h"

layout(location = 0) flat in vec4 in_irradiance;
layout(location = 0) out vec4 out_receiver;

void main() {
  vec3 e = finite3(max(in_irradiance.rgb, vec3(0.0f)));
  out_receiver = vec4(e, luminance(e) * in_irradiance.w);
}
