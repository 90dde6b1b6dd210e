#include "shading/shadow_plan.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

namespace mrgi::shading {
namespace {

// An up vector not parallel to `dir`.
glm::vec3 up_for(const glm::vec3& dir) {
  return std::abs(dir.y) > 0.99f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
}

glm::mat4 perspective_view_proj(const glm::vec3& eye, const glm::vec3& dir, float fov_rad) {
  const glm::mat4 view = glm::lookAtRH(eye, eye + dir, up_for(dir));
  const glm::mat4 proj = glm::perspectiveRH_ZO(fov_rad, 1.0f, kShadowNear, kShadowFar);
  return proj * view;
}

const glm::vec3 kCubeDirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

void Bounds::add(const glm::vec3& a, const glm::vec3& b) {
  if (empty) {
    lo = a;
    hi = b;
    empty = false;
  } else {
    lo = glm::min(lo, a);
    hi = glm::max(hi, b);
  }
}

int cube_face_of(const glm::vec3& d) {
  const glm::vec3 a = glm::abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0f ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0f ? 2 : 3;
  return d.z >= 0.0f ? 4 : 5;
}

Expected<ShadowPlan> plan_shadow_maps(const SceneDesc& scene, const Bounds& bounds) {
  ShadowPlan plan;
  MRGI_TRY(plan_shadow_maps(scene.lights, bounds, scene.path + ": lights", plan));
  return plan;
}

Status plan_shadow_maps(const std::vector<LightDesc>& lights, const Bounds& bounds,
                        const std::string& where, ShadowPlan& plan) {
  plan.primary.clear();
  plan.virtual_only.clear();
  plan.real_lamps = plan.virtual_lamps = 0;
  plan.light_set = shader::LightSet{};
  if (lights.size() > MRGI_MAX_LIGHTS)
    return fail(ErrorKind::BadInput,
                where + ": " + std::to_string(lights.size()) +
                    " lamps, the direct-light block supports at most " +
                    std::to_string(MRGI_MAX_LIGHTS));
  plan.light_set.count = glm::ivec4(int(lights.size()), 0, 0, 0);
  for (size_t i = 0; i < lights.size(); ++i) {
    const LightDesc& l = lights[i];
    const int li = int(i);
    shader::ShadowLight& g = plan.light_set.lights[i];
    glm::vec3 dir = l.direction;
    const float len = glm::length(dir);
    if (l.type != LightType::Point && !(len > 1e-6f))
      return fail(ErrorKind::BadInput, where + "[" + std::to_string(i) +
                                           "].direction: must not be zero for a spot or "
                                           "directional lamp");
    dir = l.type == LightType::Point ? glm::vec3(0.0f, -1.0f, 0.0f) : dir / len;
    const int type = l.type == LightType::Point ? MRGI_LIGHT_POINT
                     : l.type == LightType::Spot ? MRGI_LIGHT_SPOT
                                                 : MRGI_LIGHT_DIRECTIONAL;
    g.position_type = glm::vec4(l.position, float(type));
    g.direction_real = glm::vec4(dir, l.real ? 1.0f : 0.0f);
    g.intensity = glm::vec4(l.color * l.intensity, 0.0f);
    const float inner = glm::radians(std::min(l.inner_angle_deg, l.outer_angle_deg));
    const float outer = glm::radians(l.outer_angle_deg);
    g.cone = glm::vec4(std::cos(inner), std::cos(outer), 0.0f, 0.0f);

    const int faces = l.type == LightType::Point ? 6 : 1;
    glm::mat4 mats[6];
    frame::LodView lod{l.position, 0.0f, 0.0f};  // for a map one texel wide
    if (l.type == LightType::Point) {
      for (int f = 0; f < 6; ++f)
        mats[f] = perspective_view_proj(l.position, kCubeDirs[f], glm::radians(90.0f));
      g.cone.z = 2.0f;  // 2 tan(45 deg)
      lod.focal_px = 1.0f / g.cone.z;
    } else if (l.type == LightType::Spot) {
      const float fov = std::min(2.0f * outer, glm::radians(kMaxSpotFovDeg));
      mats[0] = perspective_view_proj(l.position, dir, fov);
      g.cone.z = 2.0f * std::tan(0.5f * fov);
      lod.focal_px = 1.0f / g.cone.z;
    } else {
      glm::vec3 centre(0.0f);
      float half = kMinOrthoHalfWidth;
      if (!bounds.empty) {
        centre = 0.5f * (bounds.lo + bounds.hi);
        half = std::max(kMinOrthoHalfWidth, kOrthoMargin * 0.5f * glm::length(bounds.hi - bounds.lo));
      } else {
        half = 5.0f;  // nothing to fit: a 10 m box around the world origin
      }
      const glm::vec3 eye = centre - dir * (0.5f * kOrthoDepth);
      const glm::mat4 view = glm::lookAtRH(eye, centre, up_for(dir));
      const glm::mat4 proj = glm::orthoRH_ZO(-half, half, -half, half, 0.0f, kOrthoDepth);
      mats[0] = proj * view;
      g.cone.w = 2.0f * half;
      lod = frame::orthographic_lod_view(centre, dir, 2.0f * half, 0.0f);  // one texel spans the map
    }
    for (int f = 0; f < faces; ++f) plan.light_set.face_view_proj[li * 6 + f] = mats[f];

    g.layers = glm::ivec4(int(plan.primary.size()), -1, faces, 0);
    for (int f = 0; f < faces; ++f) {
      ShadowFace sf;
      sf.light = li;
      sf.face = f;
      sf.layer = int(plan.primary.size());
      sf.view_proj = mats[f];
      sf.lod_per_texel = lod;
      sf.real_casters = true;
      sf.virtual_casters = !l.real;  // a virtual lamp's single map holds every caster
      plan.primary.push_back(sf);
    }
    if (l.real) {
      ++plan.real_lamps;
      g.layers.y = int(plan.virtual_only.size());
      for (int f = 0; f < faces; ++f) {
        ShadowFace sf;
        sf.light = li;
        sf.face = f;
        sf.layer = int(plan.virtual_only.size());
        sf.view_proj = mats[f];
        sf.lod_per_texel = lod;
        sf.virtual_casters = true;
        plan.virtual_only.push_back(sf);
      }
    } else {
      ++plan.virtual_lamps;
    }
  }
  return ok_status();
}

}  // namespace mrgi::shading
