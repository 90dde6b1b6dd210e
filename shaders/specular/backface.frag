#version 460
// The refractive objects' back faces seen from the camera (Wyman 2005's first pass, caustics-DIR
// paper Sec. 3.2): world position and outward normal of the nearest back face at each pixel,
// where the refracted ray leaves the object. Drawn with gi/rsm_mesh.vert (the camera's
// world_to_clip as its matrix), front faces culled.
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_albedo;
layout(location = 4) flat in vec4 in_material;
layout(location = 0) out vec4 out_position;  // xyz world, w 1 (0: no back face)
layout(location = 1) out vec4 out_normal;    // xyz outward unit normal

void main() {
  vec3 n = normalize(in_normal);
  out_position = vec4(in_world, 1.0f);
  out_normal = vec4(any(isnan(n)) ? vec3(0.0f, 0.0f, 1.0f) : n, 0.0f);
}
