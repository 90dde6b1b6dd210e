#version 460
// Shadow map of triangle meshes (virtual objects, real proxy geometry): depth only.
layout(location = 0) in vec3 in_position;  // world space
layout(push_constant) uniform Face { mat4 view_proj; } face;
void main() { gl_Position = face.view_proj * vec4(in_position, 1.0f); }
