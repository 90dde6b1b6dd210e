#version 460
// Reflective shadow map of the real scene as the depth camera sees it (gi/rsm.h): one vertex per
// point of a grid over the real G-buffer, drawn with the caster index list
// (shading/shadow_caster_indices.comp drops triangles with a missing or discontinuous vertex).
// Hands on what gi/rsm.frag writes: world position, normal, the reconstructed albedo.
layout(set = 0, binding = 0) uniform sampler2D real_position;  // xyz world, w depth (0 invalid)
layout(set = 0, binding = 1) uniform sampler2D real_normal;    // xyz world
layout(set = 0, binding = 2) uniform sampler2D real_albedo;    // rgb linear, a valid
layout(push_constant) uniform RsmDraw {
  mat4 view_proj;
  vec4 light;   // xyz: lamp position (w > 0: the texel's solid angle at the map's centre, sr) or
                // travel direction (w < 0: minus the texel's area across the beam, m^2)
  vec4 colour;  // rgb: colour x intensity; w: spot cos outer (-2: no cone)
  vec4 axis;    // xyz: the map's view axis; w: spot cos inner
  ivec4 misc;   // x: grid stride (G-buffer pixels between points); y: material (-1: proxy);
                // z: a proxy's hint colour, linear RGB8 packed; w: grid points per row
} draw;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_albedo;   // rgb linear albedo
layout(location = 4) flat out vec4 out_material;  // gi/rsm.frag's in_material

void main() {
  int stride = max(draw.misc.x, 1);
  int row = max(draw.misc.w, 1);  // grid points per row over the G-buffer's used extent
  ivec2 g = ivec2(gl_VertexIndex % row, gl_VertexIndex / row) * stride;
  vec4 p = texelFetch(real_position, g, 0);
  out_world = p.xyz;
  out_normal = texelFetch(real_normal, g, 0).xyz;
  vec4 a = texelFetch(real_albedo, g, 0);
  out_albedo = vec4(a.w > 0.0f ? a.xyz : vec3(0.0f), 1.0f);
  out_uv = vec2(0.0f);
  out_material = vec4(-1.0f, 0.0f, -1.0f, 0.0f);  // diffuse (the paper's real specular is 0)
  gl_Position = draw.view_proj * vec4(p.xyz, 1.0f);
}
