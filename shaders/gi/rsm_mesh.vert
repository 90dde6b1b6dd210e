#version 460
// Reflective shadow map of triangle meshes (gi/rsm.h): the virtual objects with their glTF
// materials, the real proxies with their material hint (push constant material < 0: `hint`).
// The material is read here and handed on flat (lavapipe gathers a fragment shader's buffer
// reads per lane; virtual.vert says more).
#extension GL_GOOGLE_include_directive : require
#include "common/scene_materials.glsl"

layout(std430, set = 0, binding = 3) readonly buffer Materials { GpuMaterial materials[]; };
layout(push_constant) uniform RsmDraw {
  mat4 view_proj;
  vec4 light;   // xyz: lamp position (w > 0: the texel's solid angle at the map's centre, sr) or
                // travel direction (w < 0: minus the texel's area across the beam, m^2)
  vec4 colour;  // rgb: colour x intensity; w: spot cos outer (-2: no cone)
  vec4 axis;    // xyz: the map's view axis; w: spot cos inner
  ivec4 misc;   // x: grid stride (G-buffer pixels between points); y: material (-1: proxy);
                // z: a proxy's hint colour, linear RGB8 packed; w: grid points per row
} draw;
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_albedo;
layout(location = 4) flat out vec4 out_material;  // gi/rsm.frag's in_material

void main() {
  out_world = in_position;
  out_normal = in_normal;
  out_uv = in_uv;
  if (draw.misc.y >= 0) {
    GpuMaterial m = materials[draw.misc.y];
    out_albedo = m.base_color_factor;
    out_material = vec4(m.params.z, m.params.x, m.params.y, 0.0f);
  } else {
    out_albedo = unpackUnorm4x8(uint(draw.misc.z));  // the proxy's material hint
    out_material = vec4(-1.0f, 0.0f, -1.0f, 0.0f);  // diffuse (the paper's real specular is 0)
  }
  gl_Position = draw.view_proj * vec4(in_position, 1.0f);
}
