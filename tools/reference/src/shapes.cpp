#include "mrgi/reference/shapes.h"

#include <algorithm>
#include <cmath>

namespace mrgi::reference {

namespace {

void transform(RefMesh& mesh, const glm::mat4& m) {
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
  for (glm::vec3& p : mesh.positions) p = glm::vec3(m * glm::vec4(p, 1.0f));
  for (glm::vec3& n : mesh.normals) n = glm::normalize(normal_matrix * n);
  // A mirroring transform flips the winding; keep the front face outside.
  if (glm::determinant(glm::mat3(m)) < 0.0f)
    for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) std::swap(mesh.indices[i + 1], mesh.indices[i + 2]);
}

// Quad p0 p1 p2 p3 (counter-clockwise seen from the front) with normal n.
void add_quad(RefMesh& mesh, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 n) {
  const uint32_t b = uint32_t(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {p0, p1, p2, p3});
  mesh.normals.insert(mesh.normals.end(), {n, n, n, n});
  mesh.uvs.insert(mesh.uvs.end(), {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}});
  mesh.indices.insert(mesh.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
}

}  // namespace

RefMesh make_plane(glm::vec2 size, const glm::mat4& object_to_world) {
  RefMesh mesh;
  const float hx = 0.5f * size.x, hz = 0.5f * size.y;
  // Seen from +y, counter-clockwise: (-x,+z) -> (+x,+z) -> (+x,-z) -> (-x,-z).
  add_quad(mesh, {-hx, 0.0f, hz}, {hx, 0.0f, hz}, {hx, 0.0f, -hz}, {-hx, 0.0f, -hz}, {0.0f, 1.0f, 0.0f});
  transform(mesh, object_to_world);
  return mesh;
}

RefMesh make_box(glm::vec3 size, const glm::mat4& object_to_world) {
  RefMesh mesh;
  const glm::vec3 h = 0.5f * size;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      glm::vec3 n(0.0f);
      n[axis] = float(sign);
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      glm::vec3 u(0.0f), v(0.0f);
      u[a1] = h[a1];
      v[a2] = h[a2];
      const glm::vec3 c = n * h[axis];
      // (u x v) points along +axis; reverse the order for the negative face.
      if (sign > 0)
        add_quad(mesh, c - u - v, c + u - v, c + u + v, c - u + v, n);
      else
        add_quad(mesh, c - u - v, c - u + v, c + u + v, c + u - v, n);
    }
  }
  transform(mesh, object_to_world);
  return mesh;
}

RefMesh make_sphere(float radius, int segments, const glm::mat4& object_to_world) {
  RefMesh mesh;
  segments = std::max(segments, 8);
  const int rings = segments / 2;
  const float pi = 3.14159265358979f;
  for (int r = 0; r <= rings; ++r) {
    const float theta = pi * float(r) / float(rings);
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * pi * float(s) / float(segments);
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
      mesh.uvs.push_back({float(s) / float(segments), float(r) / float(rings)});
    }
  }
  const uint32_t row = uint32_t(segments + 1);
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = uint32_t(r) * row + uint32_t(s), b = a + row;
      // Counter-clockwise seen from outside; degenerate pole triangles are skipped.
      if (r != 0) mesh.indices.insert(mesh.indices.end(), {a, b, a + 1});
      if (r != rings - 1) mesh.indices.insert(mesh.indices.end(), {a + 1, b, b + 1});
    }
  transform(mesh, object_to_world);
  return mesh;
}

}  // namespace mrgi::reference
