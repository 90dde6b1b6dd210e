#version 460
// A lamp's photon G-buffer (caustics-DIR paper Sec. 5.2, PGBuf): the reflective and refractive
// objects' front faces seen from a spot lamp, world position (w: 2 + the material's index) and
// normal. Drawn with gi/rsm_mesh.vert (push constant misc.y: the draw's material).
layout(push_constant) uniform RsmDraw {
  mat4 view_proj;
  vec4 light;
  vec4 colour;
  vec4 axis;
  ivec4 misc;  // y: material
} draw;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_albedo;
layout(location = 4) flat in vec4 in_material;
layout(location = 0) out vec4 out_position;  // xyz world, w 2 + material (0: no object)
layout(location = 1) out vec4 out_normal;    // xyz unit, facing the lamp

void main() {
  vec3 n = normalize(in_normal);
  if (any(isnan(n))) n = normalize(draw.light.xyz - in_world);
  if (dot(n, draw.light.xyz - in_world) < 0.0f) n = -n;
  out_position = vec4(in_world, 2.0f + float(max(draw.misc.y, 0)));
  out_normal = vec4(n, 0.0f);
}
