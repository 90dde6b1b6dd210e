#version 460
// Virtual G-buffer: the glTF objects (already in world space) seen by the colour camera.
#extension GL_GOOGLE_include_directive : require
#include "common/frame_constants.glsl"

layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame; };
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out float out_view_z;

void main() {
  out_world = in_position;
  out_normal = in_normal;
  out_uv = in_uv;
  out_view_z = (frame.world_to_camera * vec4(in_position, 1.0f)).z;
  gl_Position = frame.world_to_clip * vec4(in_position, 1.0f);
}
