// Small closed meshes for the unit tests of what is fitted to or measured on a mesh (sphere
// proxies, oriented patches, silhouettes): triangles wound counter-clockwise seen from outside.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mrgi::test {

struct TestMesh {
  std::vector<glm::vec3> p;
  std::vector<uint32_t> i;
};

// An axis-aligned box from corner lo to corner hi, two triangles a face.
inline TestMesh box_mesh(glm::vec3 lo, glm::vec3 hi) {
  TestMesh m;
  for (int k = 0; k < 8; ++k) m.p.emplace_back(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
  // Faces -x, +x, -y, +y, -z, +z.
  const uint32_t f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : f) m.i.insert(m.i.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  return m;
}

// A UV sphere of radius r round c: `rings` bands from pole to pole, `segments` round each.
inline TestMesh uv_sphere_mesh(glm::vec3 c, float r, int rings = 24, int segments = 48) {
  TestMesh m;
  const float pi = 3.14159265358979f;
  for (int a = 0; a <= rings; ++a)
    for (int b = 0; b <= segments; ++b) {
      const float t = pi * float(a) / float(rings), ph = 2.0f * pi * float(b) / float(segments);
      m.p.push_back(c + r * glm::vec3(std::sin(t) * std::cos(ph), std::cos(t), std::sin(t) * std::sin(ph)));
    }
  for (int a = 0; a < rings; ++a)
    for (int b = 0; b < segments; ++b) {
      const uint32_t i0 = uint32_t(a * (segments + 1) + b), i1 = i0 + 1, i2 = i0 + uint32_t(segments + 1), i3 = i2 + 1;
      m.i.insert(m.i.end(), {i0, i1, i2, i1, i3, i2});
    }
  return m;
}

}  // namespace mrgi::test
