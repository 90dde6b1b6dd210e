// Points on the virtual objects' triangles (full detail), shared by the passes that need the
// virtual surfaces as a point cloud: the ISM splat (ism_splat_virtual.comp) and the bounce light
// source (vpl_bounce.comp). gi/ism.h uploads the ranges (VirtualTriangles). The including shader
// declares the buffers Vertices { float vertex_words[]; } (technique::GpuVertex: position,
// normal, uv), Indices { uint indices[]; } and Ranges { ivec4 ranges[]; } (per draw range: x
// first index, y triangles, z vertex offset, w triangles before it).
#ifndef MRGI_VIRTUAL_POINTS_GLSL
#define MRGI_VIRTUAL_POINTS_GLSL

struct VirtualPoint {
  vec3 position;  // world (m)
  vec3 normal;    // unit, the vertex normals interpolated (the face's where they cancel)
  vec2 uv;
  float area;     // the triangle's area times the triangle count (m^2): a point's share of the
                  // objects' area over uniformly picked triangles is its mean over the picks
  int range;      // the draw range (its material)
};

vec3 virtual_vertex_position(uint v) { return vec3(vertex_words[v * 8u], vertex_words[v * 8u + 1u], vertex_words[v * 8u + 2u]); }
vec3 virtual_vertex_normal(uint v) { return vec3(vertex_words[v * 8u + 3u], vertex_words[v * 8u + 4u], vertex_words[v * 8u + 5u]); }
vec2 virtual_vertex_uv(uint v) { return vec2(vertex_words[v * 8u + 6u], vertex_words[v * 8u + 7u]); }

// u.x picks one of `triangles` uniformly; (u.y, u.z) a uniform point on it (sqrt warp).
VirtualPoint virtual_point(vec3 u, int triangles, int range_count) {
  int t = min(int(u.x * float(triangles)), triangles - 1);
  int lo = 0, hi = range_count - 1;  // the range holding triangle t
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (ranges[mid].w <= t) lo = mid; else hi = mid - 1;
  }
  ivec4 range = ranges[lo];
  uint first = uint(range.x + 3 * (t - range.w));
  uint base = uint(range.z);
  uint ia = base + indices[first], ib = base + indices[first + 1u], ic = base + indices[first + 2u];
  vec3 a = virtual_vertex_position(ia), b = virtual_vertex_position(ib), c = virtual_vertex_position(ic);
  float su = sqrt(u.y);
  vec3 w = vec3(1.0f - su, su * (1.0f - u.z), su * u.z);
  VirtualPoint p;
  p.position = a * w.x + b * w.y + c * w.z;
  vec3 face = cross(b - a, c - a);
  p.area = 0.5f * length(face) * float(triangles);
  vec3 n = virtual_vertex_normal(ia) * w.x + virtual_vertex_normal(ib) * w.y + virtual_vertex_normal(ic) * w.z;
  float len = length(n);
  float flen = length(face);
  p.normal = len > 1e-6f ? n / len : (flen > 0.0f ? face / flen : vec3(0.0f, 1.0f, 0.0f));
  p.uv = virtual_vertex_uv(ia) * w.x + virtual_vertex_uv(ib) * w.y + virtual_vertex_uv(ic) * w.z;
  p.range = lo;
  return p;
}

#endif
