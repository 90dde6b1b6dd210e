// The environment occlusion's result (shading/environment_occlusion.h) read back at internal
// resolution, for every shading pass that takes the virtual objects' occlusion of the ambient
// off L_rv. The includer declares `env_occlusion` (rgba16f: rgb the irradiance hidden, a the
// surface key) and frame_constants.glsl's `frame`.
#ifndef MRGI_ENV_OCCLUSION_LOOKUP_GLSL
#define MRGI_ENV_OCCLUSION_LOOKUP_GLSL

// At a pixel whose surface key (distance to the camera, negative on a virtual surface) is `key`,
// from a grid of `divisor` x `divisor` internal pixels a texel: bilinear over the texels on the
// same surface (key within 5 % + 2 cm), else over those of the same kind (real / virtual), else
// none, so an object's occlusion does not bleed onto the floor behind its edge.
vec3 hidden_environment(ivec2 pixel, float key, int divisor) {
  if (divisor == 1) return imageLoad(env_occlusion, pixel).rgb;
  ivec2 low = (frame.internal_output_size.xy + divisor - 1) / divisor;
  vec2 f = (vec2(pixel) + 0.5f) / float(divisor) - 0.5f;
  ivec2 i0 = ivec2(floor(f));
  vec2 t = f - vec2(i0);
  vec3 same = vec3(0.0f), kind = vec3(0.0f);
  float w_same = 0.0f, w_kind = 0.0f;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    vec4 tap = imageLoad(env_occlusion, clamp(i0 + o, ivec2(0), low - 1));
    float w = (o.x == 1 ? t.x : 1.0f - t.x) * (o.y == 1 ? t.y : 1.0f - t.y) + 1e-4f;
    if (tap.a * key > 0.0f) {
      kind += w * tap.rgb;
      w_kind += w;
      if (abs(tap.a - key) <= 0.05f * abs(key) + 0.02f) {
        same += w * tap.rgb;
        w_same += w;
      }
    }
  }
  return w_same > 0.0f ? same / w_same : (w_kind > 0.0f ? kind / w_kind : vec3(0.0f));
}

// The ambient irradiance `e_ambient` of L_rv at (pixel, p) less what the objects hide there
// (never below 0); `divisor` 0: no occlusion this frame.
vec3 occluded_ambient(vec3 e_ambient, ivec2 pixel, vec3 p, bool is_virtual, int divisor) {
  if (divisor <= 0) return e_ambient;
  float key = distance(p, frame.camera_world.xyz);
  return max(e_ambient - hidden_environment(pixel, is_virtual ? -key : key, divisor), vec3(0.0f));
}

#endif
