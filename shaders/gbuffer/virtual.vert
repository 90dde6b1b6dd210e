#version 460
// Virtual G-buffer, vertex stage: gbuffer/virtual_vertex.glsl.
#extension GL_GOOGLE_include_directive : require
#include "gbuffer/virtual_vertex.glsl"
