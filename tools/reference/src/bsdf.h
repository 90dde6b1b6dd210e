// BSDFs of the reference path tracer (models documented in mrgi/reference/path_tracer.h).
// Directions are unit vectors pointing away from the surface; wo toward the viewer.
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "mrgi/reference/path_tracer.h"
#include "sampling.h"

namespace mrgi::reference {

// The material at one hit, with texture already applied.
struct ShadingPoint {
  MaterialType type = MaterialType::Diffuse;
  glm::vec3 base{0.8f};
  float alpha = 0.25f;     // GGX alpha
  float metallic = 0.0f;
  float ior = 1.5f;
  bool is_delta() const { return type == MaterialType::Mirror || type == MaterialType::Glass; }
};

struct BsdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};  // f * |cos| / pdf (delta lobes: the lobe's reflectance / choice prob)
  float pdf = 0.0f;        // solid angle pdf; 0 for delta lobes
  bool delta = false;
};

namespace bsdf_detail {
inline float ggx_d(float cos_h, float a2) {
  const float d = cos_h * cos_h * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}
inline float smith_lambda(float cos_t, float a2) {
  const float c2 = std::max(cos_t * cos_t, 1e-8f);
  const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (-1.0f + std::sqrt(1.0f + a2 * tan2));
}
inline glm::vec3 schlick(const glm::vec3& f0, float cos_t) {
  const float m = std::pow(glm::clamp(1.0f - cos_t, 0.0f, 1.0f), 5.0f);
  return f0 + (glm::vec3(1.0f) - f0) * m;
}
// Unpolarised Fresnel reflectance of a smooth dielectric; eta = n_incident / n_transmitted.
inline float fresnel_dielectric(float cos_i, float eta, float* cos_t_out) {
  const float sin2_t = eta * eta * std::max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) {
    *cos_t_out = 0.0f;
    return 1.0f;  // total internal reflection
  }
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  *cos_t_out = cos_t;
  return 0.5f * (rs * rs + rp * rp);
}
inline float glossy_spec_probability(const ShadingPoint& sp) { return 0.5f + 0.5f * sp.metallic; }
inline glm::vec3 glossy_f0(const ShadingPoint& sp) { return glm::mix(glm::vec3(0.04f), sp.base, sp.metallic); }
inline glm::vec3 glossy_diffuse(const ShadingPoint& sp) { return sp.base * ((1.0f - sp.metallic) * 0.96f / kPi); }
}  // namespace bsdf_detail

// f(wo, wi) and the pdf of bsdf_sample choosing wi, in the local frame (n = +z) on the side of
// wo. Non-delta materials only.
inline glm::vec3 bsdf_eval_local(const ShadingPoint& sp, const glm::vec3& wo, const glm::vec3& wi, float* pdf) {
  using namespace bsdf_detail;
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  if (sp.type == MaterialType::Diffuse) {
    *pdf = wi.z / kPi;
    return sp.base / kPi;
  }
  const glm::vec3 h = glm::normalize(wo + wi);
  const float a2 = sp.alpha * sp.alpha;
  const float d = ggx_d(h.z, a2);
  const float g2 = 1.0f / (1.0f + smith_lambda(wo.z, a2) + smith_lambda(wi.z, a2));
  const float wo_h = std::max(glm::dot(wo, h), 1e-6f);
  const glm::vec3 spec = schlick(glossy_f0(sp), wo_h) * (d * g2 / (4.0f * wo.z * wi.z));
  const float ps = glossy_spec_probability(sp);
  *pdf = ps * d * h.z / (4.0f * wo_h) + (1.0f - ps) * wi.z / kPi;
  return spec + glossy_diffuse(sp);
}

// Samples wi for wo (local frame, n = +z outward for glass, toward wo for opaque materials).
inline bool bsdf_sample_local(const ShadingPoint& sp, const glm::vec3& wo, float u_lobe, glm::vec2 u,
                              BsdfSample& out) {
  using namespace bsdf_detail;
  switch (sp.type) {
    case MaterialType::Diffuse: {
      if (wo.z <= 0.0f) return false;
      out.wi = sample_cosine_hemisphere(u);
      out.pdf = out.wi.z / kPi;
      out.weight = sp.base;
      out.delta = false;
      return out.pdf > 0.0f;
    }
    case MaterialType::Glossy: {
      if (wo.z <= 0.0f) return false;
      const float ps = glossy_spec_probability(sp);
      if (u_lobe < ps) {
        const float a2 = sp.alpha * sp.alpha;
        const float cos2 = (1.0f - u.x) / (1.0f + (a2 - 1.0f) * u.x);
        const float cos_h = std::sqrt(cos2), sin_h = std::sqrt(std::max(0.0f, 1.0f - cos2));
        const float phi = 2.0f * kPi * u.y;
        const glm::vec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
        out.wi = glm::reflect(-wo, h);
      } else {
        out.wi = sample_cosine_hemisphere(u);
      }
      if (out.wi.z <= 0.0f) return false;
      float pdf = 0.0f;
      const glm::vec3 f = bsdf_eval_local(sp, wo, out.wi, &pdf);
      if (pdf <= 0.0f) return false;
      out.pdf = pdf;
      out.weight = f * (out.wi.z / pdf);
      out.delta = false;
      return true;
    }
    case MaterialType::Mirror: {
      if (wo.z <= 0.0f) return false;
      out.wi = glm::vec3(-wo.x, -wo.y, wo.z);
      out.weight = sp.base;
      out.pdf = 0.0f;
      out.delta = true;
      return true;
    }
    case MaterialType::Glass: {
      const bool entering = wo.z > 0.0f;
      const float cos_i = std::abs(wo.z);
      const float eta = entering ? 1.0f / sp.ior : sp.ior;
      float cos_t = 0.0f;
      const float fr = fresnel_dielectric(cos_i, eta, &cos_t);
      out.delta = true;
      out.pdf = 0.0f;
      if (u_lobe < fr) {
        out.wi = glm::vec3(-wo.x, -wo.y, wo.z);
        out.weight = glm::vec3(1.0f);
      } else {
        // Refraction: wi = -eta * wo + (eta cos_i - cos_t) n, on the far side of the surface.
        const float side = entering ? 1.0f : -1.0f;
        const glm::vec3 n(0.0f, 0.0f, side);
        out.wi = glm::normalize(-eta * wo + (eta * cos_i - cos_t) * n);
        // No eta^2 radiance scaling: it cancels for closed objects viewed from air.
        out.weight = sp.base;
      }
      return true;
    }
  }
  return false;
}

}  // namespace mrgi::reference
