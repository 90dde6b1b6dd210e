// Random numbers and sampling helpers of the reference path tracer.
// Random numbers are a pure function of a key and a dimension (counter-based), so a sample draws
// the same numbers whichever thread runs it and whichever scene (L_r or L_rv) it is traced in.
#pragma once
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "shared/mrgi_shared.h"

namespace mrgi::reference {

inline constexpr float kPi = 3.14159265358979323846f;

// SplitMix64 finaliser: a bijective 64-bit mixer with full avalanche.
inline uint64_t mix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

inline uint64_t hash_key(uint64_t a, uint64_t b) { return mix64(a ^ mix64(b)); }

// The random stream of one sample: uniform(dim) is the same for the same key and dim.
struct SampleRng {
  uint64_t key = 0;
  float uniform(uint32_t dim) const {
    const uint64_t h = mix64(key ^ (uint64_t(dim) * 0xD1B54A32D192ED03ull));
    return float(h >> 40) * (1.0f / 16777216.0f);  // 24 bits: exactly representable, < 1
  }
  glm::vec2 uniform2(uint32_t dim) const { return {uniform(dim), uniform(dim + 1)}; }
};

// Dimension layout: each bounce owns a block so that adding a lamp or a lobe does not shift the
// numbers another decision uses.
namespace dims {
inline constexpr uint32_t kPixelJitter = 0xFFFF0000u;  // 2 dims
inline constexpr uint32_t kBounceStride = 4096;
inline constexpr uint32_t kBsdfLobe = 0;      // 1 dim
inline constexpr uint32_t kBsdfDir = 1;       // 2 dims
inline constexpr uint32_t kRoulette = 3;      // 1 dim
inline constexpr uint32_t kLightBase = 16;    // 4 dims per lamp
inline uint32_t at(int bounce, uint32_t slot) { return uint32_t(bounce) * kBounceStride + slot; }
}  // namespace dims

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame3 {
  glm::vec3 t, b, n;
  explicit Frame3(const glm::vec3& normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float bb = n.x * n.y * a;
    t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
  }
  glm::vec3 to_world(const glm::vec3& v) const { return v.x * t + v.y * b + v.z * n; }
  glm::vec3 to_local(const glm::vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
};

inline glm::vec3 sample_cosine_hemisphere(glm::vec2 u) {
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x))};
}

inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
inline float max_component(const glm::vec3& c) { return std::max(c.r, std::max(c.g, c.b)); }
inline bool finite3(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Balance heuristic for one sample from each of two strategies.
inline float mis_balance(float pdf_a, float pdf_b) {
  return pdf_a + pdf_b > 0.0f ? pdf_a / (pdf_a + pdf_b) : 0.0f;
}

// Spot cone falloff and camera response come from the header the shaders use, so the runtime
// and the reference see the same lamps and the same camera.
using shader::camera_response;
using shader::spot_falloff;

}  // namespace mrgi::reference
