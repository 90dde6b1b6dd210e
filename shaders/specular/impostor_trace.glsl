// The specular stage's ray searches, shared by the camera's pass (trace.comp) and the lamps'
// photon pass (photons.comp). The including shader declares `specular` (SpecularUbo), the
// impostor atlas (impostor_position, impostor_normal, impostor_albedo) and the back faces of the
// view the refraction starts in (back_position, back_normal), and includes
// shared/specular_math.h and specular/specular_params.glsl.
#ifndef MRGI_SPECULAR_IMPOSTOR_TRACE_GLSL
#define MRGI_SPECULAR_IMPOSTOR_TRACE_GLSL

// The atlas texel of set s in direction d from its centre.
ivec2 impostor_texel(SpecularSet s, vec3 d) {
  vec3 f = specular_cube_face(d);
  int face = int(f.z);
  int size = s.atlas.z;
  ivec2 block = ivec2(face - 3 * (face / 3), face / 3);
  return s.atlas.xy + block * size + clamp(ivec2(f.xy * float(size)), ivec2(0), ivec2(size - 1));
}

// Distance from the centre of the impostor surface in the direction of x (1e30: none there).
float impostor_distance(SpecularSet s, vec3 x) {
  vec4 p = imageLoad(impostor_position, impostor_texel(s, x - s.centre.xyz));
  return p.w > 0.5f ? distance(p.xyz, s.centre.xyz) : 1e30f;
}

// f(t) = |x(t) - c| - impostor distance: < 0 in front of the surface, >= 0 behind it.
float impostor_gap(SpecularSet s, vec3 o, vec3 d, float t) {
  vec3 x = o + d * t;
  return distance(x, s.centre.xyz) - impostor_distance(s, x);
}

struct Hit {
  bool found;
  float t;  // along the ray
  vec3 position, normal, albedo;
  bool real;
};

// The first crossing of the ray o + t d (t > 0) with set s's impostor surface. Linear search at
// t_k = r u_k / (1 - u_k), u_k uniform up to the impostors' far plane (dense within r of the
// object, where nearby surfaces bend the reflection most, and reaching a far wall in the last
// steps), then secant steps on the bracketing interval. A crossing where the gap jumps by more
// than a step's worth is the silhouette of a nearer surface the ray passes behind (the
// single-layer impostor's missing back side), not a hit: the search goes on.
const float kImpostorFar_m = 50.0f;  // specular.cpp's far plane
Hit trace_impostor(SpecularSet s, vec3 o, vec3 d) {
  Hit h;
  h.found = false;
  int n = max(specular.counts.y, 1);
  // The search's scale: the object's size, at least a quarter metre (the table it stands on and
  // the things beside it are that near).
  float r = max(s.centre.w, 0.25f);
  float u_max = kImpostorFar_m / (r + kImpostorFar_m);
  float t_prev = 0.0f;
  float f_prev = impostor_gap(s, o, d, 1e-4f);
  float t_hit = -1.0f;
  if (f_prev >= 0.0f && f_prev < 0.5f * r) {
    t_hit = 1e-4f;  // the ray starts at or under the surface (an object resting on it)
  } else {
    for (int k = 1; k <= n; ++k) {
      float u = u_max * float(k) / float(n);
      float t = r * u / (1.0f - u);
      float f = impostor_gap(s, o, d, t);
      if (f_prev < 0.0f && f >= 0.0f) {
        float ta = t_prev, fa = f_prev, tb = t, fb = f;
        for (int i = 0; i < specular.counts.z; ++i) {
          float tm = ta + (tb - ta) * clamp(-fa / max(fb - fa, 1e-9f), 0.05f, 0.95f);
          float fm = impostor_gap(s, o, d, tm);
          if (fm < 0.0f) { ta = tm; fa = fm; } else { tb = tm; fb = fm; }
        }
        // A crossing of the surface has the impostor's point on the ray, within its texel's size
        // and what is left of the bracket; at a silhouette the point is on the nearer surface,
        // off the ray that passed behind it.
        vec3 q = imageLoad(impostor_position, impostor_texel(s, o + d * tb - s.centre.xyz)).xyz;
        vec3 oq = q - o;
        float off_ray = length(oq - d * dot(oq, d));
        float texel_m = 2.0f * distance(q, s.centre.xyz) / float(s.atlas.z);
        if (off_ray <= 2.0f * texel_m + (tb - ta)) {
          t_hit = tb;
          break;
        }
      }
      t_prev = t;
      f_prev = f;
    }
  }
  if (t_hit < 0.0f) return h;
  ivec2 texel = impostor_texel(s, o + d * t_hit - s.centre.xyz);
  vec4 p = imageLoad(impostor_position, texel);
  if (!(p.w > 0.5f)) return h;
  h.t = t_hit;
  h.found = true;
  h.position = p.xyz;
  h.normal = normalize(imageLoad(impostor_normal, texel).xyz);
  if (dot(h.normal, d) > 0.0f) h.normal = -h.normal;  // the side the ray meets
  h.albedo = imageLoad(impostor_albedo, texel).rgb;
  h.real = p.w < 1.5f;
  return h;
}

// ---- two-sided refraction ---------------------------------------------------------------------

struct Refraction {
  vec3 exit_p, exit_d;
  float transmission;  // (1 - F) at both interfaces (a thin sheet: the one)
};

// Wyman 2005's two refractions through an object whose back faces `view_proj` (Vulkan clip of
// a perspective view, `size` texels) drew into back_position / back_normal over `rect` (xy the
// first texel, zw one past the last; the rest is not read): Snell at the front
// face (p, unit normal n facing the incoming direction d), the exit point found along the
// refracted ray in the back faces (a search instead of Wyman's interpolated distance estimate:
// exact where the buffer holds the exit, and no per-vertex precomputation), Snell there. Under
// total internal reflection at the exit the light stays inside; it is followed along the
// internal mirror direction from the exit point (one bounce, no further search). Without a back
// face at p's texel (an open or one-sided surface) the object is a thin sheet: the ray goes on.
vec3 clip_texel(mat4 view_proj, vec3 x, ivec2 size) {  // xy texel, z view depth (clip w)
  vec4 c = view_proj * vec4(x, 1.0f);
  if (!(c.w > 1e-6f)) return vec3(-1.0f, -1.0f, -1.0f);
  return vec3((c.xy / c.w * 0.5f + 0.5f) * vec2(size), c.w);
}
bool back_behind(mat4 view_proj, vec3 x, ivec2 size, ivec4 rect, out bool inside) {
  vec3 q = clip_texel(view_proj, x, size);
  inside = q.z > 0.0f && all(greaterThanEqual(q.xy, vec2(rect.xy))) && all(lessThan(q.xy, vec2(rect.zw)));
  if (!inside) return true;
  vec4 b = imageLoad(back_position, ivec2(q.xy));
  if (!(b.w > 0.5f)) return true;  // left the object's silhouette
  return q.z >= (view_proj * vec4(b.xyz, 1.0f)).w;
}
Refraction refract_through(vec3 p, vec3 d, vec3 n, float ior, mat4 view_proj, ivec2 size, ivec4 rect) {
  Refraction r;
  float cos_i = max(-dot(d, n), 0.0f);
  float f1 = fresnel_dielectric(cos_i, 1.0f / ior);
  r.exit_p = p;
  r.exit_d = d;
  r.transmission = 1.0f - f1;
  vec4 t1 = refract_or_reflect(d, n, 1.0f / ior);
  vec3 q = clip_texel(view_proj, p, size);
  ivec2 pt = clamp(ivec2(q.xy), rect.xy, rect.zw - 1);
  vec4 back = imageLoad(back_position, pt);
  if (!(back.w > 0.5f) || t1.w < 0.5f) return r;
  float d_v = distance(back.xyz, p);
  int steps = max(specular.counts.w, 1);
  float t_lo = 0.0f, t_hi = -1.0f;
  vec3 exit_n = imageLoad(back_normal, pt).xyz;
  r.exit_p = back.xyz;
  bool inside;
  for (int k = 1; k <= steps; ++k) {
    float t = 2.0f * d_v * float(k) / float(steps);
    if (back_behind(view_proj, p + t1.xyz * t, size, rect, inside)) {
      if (inside) t_hi = t;
      break;
    }
    t_lo = t;
  }
  if (t_hi > 0.0f) {
    for (int i = 0; i < 4; ++i) {  // bisection to the back face
      float t = 0.5f * (t_lo + t_hi);
      if (back_behind(view_proj, p + t1.xyz * t, size, rect, inside)) t_hi = t; else t_lo = t;
    }
    vec3 x = p + t1.xyz * t_hi;
    vec3 c = clip_texel(view_proj, x, size);
    ivec2 e = clamp(ivec2(c.xy), rect.xy, rect.zw - 1);
    vec4 b = imageLoad(back_position, e);
    r.exit_p = b.w > 0.5f ? b.xyz : x;
    if (b.w > 0.5f) exit_n = imageLoad(back_normal, e).xyz;
  }
  exit_n = normalize(exit_n);
  if (dot(exit_n, t1.xyz) < 0.0f) exit_n = -exit_n;  // outward, along the ray
  vec4 t2 = refract_or_reflect(t1.xyz, -exit_n, ior);
  r.exit_d = t2.xyz;
  float f2 = t2.w > 0.5f ? fresnel_dielectric(max(dot(t1.xyz, exit_n), 0.0f), ior) : 0.0f;
  r.transmission = (1.0f - f1) * (1.0f - f2);
  return r;
}

#endif  // MRGI_SPECULAR_IMPOSTOR_TRACE_GLSL
