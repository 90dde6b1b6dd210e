#version 460
// The virtual objects' coverage at the output resolution, vertex stage: gbuffer/
// virtual_vertex.glsl with only what virtual_coverage.frag reads.
#extension GL_GOOGLE_include_directive : require
#define MRGI_VIRTUAL_COVERAGE
#include "gbuffer/virtual_vertex.glsl"
