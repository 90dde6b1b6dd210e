// Light transport of the reference path tracer (model in mrgi/reference/path_tracer.h).
#include "path_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mrgi::reference {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Ray origin offset scaled with the magnitude of the position, against self-intersection.
inline float ray_epsilon(const glm::vec3& p) {
  return 1e-4f * (1.0f + std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
}

glm::vec3 sample_texture(const ImageRGBF& tex, glm::vec2 uv) {
  const float fx = (uv.x - std::floor(uv.x)) * tex.width - 0.5f;
  const float fy = (uv.y - std::floor(uv.y)) * tex.height - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float ax = fx - x0, ay = fy - y0;
  auto texel = [&](int x, int y) {
    x = ((x % tex.width) + tex.width) % tex.width;
    y = ((y % tex.height) + tex.height) % tex.height;
    const float* p = tex.at(x, y);
    return glm::vec3(p[0], p[1], p[2]);
  };
  return glm::mix(glm::mix(texel(x0, y0), texel(x0 + 1, y0), ax), glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), ax),
                  ay);
}

}  // namespace

Integrator::Integrator(const PathTracer::Impl& scene, const RefCamera& camera, const RenderSettings& settings)
    : scene_(scene), camera_(camera), settings_(settings) {
  cam_rot_ = glm::mat3(glm::mat3(camera.camera_to_world));
  cam_pos_ = glm::vec3(camera.camera_to_world[3]);
  frame_key_ = hash_key(hash_key(0x6D726769ull, settings.seed), settings.frame);
}

bool Integrator::camera_ray(double px, double py, glm::vec3* origin, glm::vec3* dir, glm::vec3* dir_cam) const {
  glm::dvec3 dc;
  if (camera_.model == RefCamera::Model::Pinhole) {
    const Intrinsics& k = camera_.pinhole;
    dc = glm::normalize(glm::dvec3((px - k.cx) / k.fx, (py - k.cy) / k.fy, 1.0));
  } else if (camera_.model == RefCamera::Model::Equirectangular) {
    constexpr double kPi = 3.14159265358979323846;
    const double theta = (py + 0.5) / camera_.height * kPi, phi = ((px + 0.5) / camera_.width - 0.5) * 2.0 * kPi;
    dc = glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  } else {
    const double dx = px - camera_.fisheye_cx, dy = py - camera_.fisheye_cy;
    const double r = std::sqrt(dx * dx + dy * dy);
    const double theta = r / camera_.fisheye_f;
    if (theta > 0.5 * camera_.fisheye_fov_deg * 3.14159265358979323846 / 180.0) return false;
    const double s = std::sin(theta);
    dc = r > 0.0 ? glm::dvec3(s * dx / r, s * dy / r, std::cos(theta)) : glm::dvec3(0.0, 0.0, 1.0);
  }
  *dir_cam = glm::vec3(dc);
  *origin = cam_pos_;
  *dir = glm::normalize(cam_rot_ * glm::vec3(dc));
  return true;
}

Hit Integrator::intersect(const glm::vec3& o, const glm::vec3& d, float tmax, bool combined) const {
  Hit hit;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  auto run = [&](RTCScene scene, bool is_virtual) {
    RTCRayHit rh;
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = hit.found ? hit.t : tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return;
    hit.found = true;
    hit.is_virtual = is_virtual;
    hit.mesh = rh.hit.geomID;
    hit.prim = rh.hit.primID;
    hit.t = rh.ray.tfar;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
  };
  run(scene_.real_scene, false);
  if (combined && !scene_.virtual_meshes.empty()) run(scene_.virtual_scene, true);
  return hit;
}

bool Integrator::occluded(const glm::vec3& o, const glm::vec3& d, float tmax, bool combined, bool* touched) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  auto blocked = [&](RTCScene scene) {
    RTCRay ray;
    ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
    ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
    ray.tnear = 0.0f;
    ray.tfar = tmax;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(scene, &ctx, &ray);
    return ray.tfar < 0.0f;
  };
  if (blocked(scene_.real_scene)) return true;
  if (combined && !scene_.virtual_meshes.empty() && blocked(scene_.virtual_scene)) {
    *touched = true;
    return true;
  }
  return false;
}

SurfacePoint Integrator::surface(const Hit& hit, const glm::vec3& o, const glm::vec3& d) const {
  const RefMesh& mesh = (hit.is_virtual ? scene_.virtual_meshes : scene_.real_meshes)[hit.mesh];
  const uint32_t i0 = mesh.indices[3 * hit.prim], i1 = mesh.indices[3 * hit.prim + 1], i2 = mesh.indices[3 * hit.prim + 2];
  const float w0 = 1.0f - hit.u - hit.v;
  SurfacePoint s;
  const glm::vec3 &a = mesh.positions[i0], &b = mesh.positions[i1], &c = mesh.positions[i2];
  s.p = w0 * a + hit.u * b + hit.v * c;
  if (!finite3(s.p)) s.p = o + hit.t * d;
  glm::vec3 ng = glm::cross(b - a, c - a);
  const float len = glm::length(ng);
  s.ng = len > 0.0f ? ng / len : -d;
  s.ns = s.ng;
  if (!mesh.normals.empty()) {
    const glm::vec3 n = w0 * mesh.normals[i0] + hit.u * mesh.normals[i1] + hit.v * mesh.normals[i2];
    const float nl = glm::length(n);
    if (nl > 0.0f && std::isfinite(nl)) {
      s.ns = n / nl;
      if (glm::dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;  // keep the shading normal on the front side
    }
  }
  if (!mesh.uvs.empty()) s.uv = w0 * mesh.uvs[i0] + hit.u * mesh.uvs[i1] + hit.v * mesh.uvs[i2];
  s.material = &scene_.materials[mesh.material];
  return s;
}

ShadingPoint Integrator::shading(const SurfacePoint& s) const {
  const RefMaterial& m = *s.material;
  ShadingPoint sp;
  sp.type = m.type;
  sp.base = m.base_color;
  if (m.texture >= 0) sp.base *= sample_texture(scene_.textures[m.texture], s.uv);
  sp.base = glm::clamp(sp.base, 0.0f, 1.0f);
  const float r = glm::clamp(m.roughness, 0.03f, 1.0f);  // alpha >= 1e-3 keeps GGX finite
  sp.alpha = r * r;
  sp.metallic = glm::clamp(m.metallic, 0.0f, 1.0f);
  sp.ior = m.ior;
  return sp;
}

float Integrator::emitter_pdf(const EmitterSet& set, float dist, float cos_light) const {
  if (set.empty() || cos_light <= 0.0f) return 0.0f;
  return dist * dist / (cos_light * set.total_area);
}

glm::vec3 Integrator::direct_light(const SurfacePoint& s, const ShadingPoint& sp, const Frame3& frame,
                                   const glm::vec3& wo_local, const glm::vec3& n_facing, const SampleRng& rng,
                                   int bounce, bool combined, bool* touched) const {
  glm::vec3 sum(0.0f);
  const glm::vec3 origin = s.p + n_facing * ray_epsilon(s.p);
  // Evaluates the BSDF toward world direction wi; zero when wi leaves below the geometric surface.
  auto eval = [&](const glm::vec3& wi, float* pdf) {
    *pdf = 0.0f;
    if (glm::dot(wi, n_facing) <= 0.0f) return glm::vec3(0.0f);
    const glm::vec3 wl = frame.to_local(wi);
    return bsdf_eval_local(sp, wo_local, wl, pdf) * std::max(wl.z, 0.0f);
  };
  uint32_t slot = dims::kLightBase;
  for (const RefLight& light : scene_.lights) {
    slot += 4;  // delta lamps draw no numbers; the block keeps later slots stable
    if (light.is_virtual && !combined) continue;
    glm::vec3 wi, li;
    float dist = kInf;
    if (light.type == RefLightType::Directional) {
      wi = -glm::normalize(light.direction);
      li = light.intensity;
    } else {
      const glm::vec3 to = light.position - s.p;
      const float d2 = glm::dot(to, to);
      if (d2 <= 0.0f) continue;
      dist = std::sqrt(d2);
      wi = to / dist;
      li = light.intensity / d2;
      if (light.type == RefLightType::Spot)
        li *= spot_falloff(glm::dot(-wi, glm::normalize(light.direction)), light.cos_outer, light.cos_inner);
    }
    if (light.is_virtual) *touched = true;  // a virtual lamp changes this path's value
    float pdf;
    const glm::vec3 fc = eval(wi, &pdf);
    if (max_component(fc * li) <= 0.0f) continue;
    const float tmax = std::isinf(dist) ? kInf : dist * (1.0f - 1e-4f) - ray_epsilon(s.p);
    if (occluded(origin, wi, tmax, combined, touched)) continue;
    sum += fc * li;
  }
  if (scene_.environment.present()) {
    glm::vec3 wi, le;
    float pdf_light;
    if (scene_.environment.sample(rng.uniform2(dims::at(bounce, slot)), &wi, &le, &pdf_light)) {
      float pdf_bsdf;
      const glm::vec3 fc = eval(wi, &pdf_bsdf);
      if (max_component(fc * le) > 0.0f && !occluded(origin, wi, kInf, combined, touched))
        sum += fc * le * (mis_balance(pdf_light, pdf_bsdf) / pdf_light);
    }
  }
  slot += 4;
  for (int part = 0; part < 2; ++part) {
    const EmitterSet& set = part == 0 ? scene_.real_emitters : scene_.virtual_emitters;
    const uint32_t this_slot = slot;
    slot += 4;
    if (set.empty() || (part == 1 && !combined)) continue;
    const float u_tri = rng.uniform(dims::at(bounce, this_slot));
    const glm::vec2 u = rng.uniform2(dims::at(bounce, this_slot + 1));
    const size_t k = std::min(size_t(std::upper_bound(set.cdf.begin(), set.cdf.end(), u_tri) - set.cdf.begin()),
                              set.triangles.size() - 1);
    const auto& meshes = part == 0 ? scene_.real_meshes : scene_.virtual_meshes;
    const RefMesh& mesh = meshes[set.triangles[k].mesh];
    const uint32_t prim = set.triangles[k].prim;
    const glm::vec3& a = mesh.positions[mesh.indices[3 * prim]];
    const glm::vec3& b = mesh.positions[mesh.indices[3 * prim + 1]];
    const glm::vec3& c = mesh.positions[mesh.indices[3 * prim + 2]];
    const float su = std::sqrt(u.x);
    const glm::vec3 q = (1.0f - su) * a + su * (1.0f - u.y) * b + su * u.y * c;
    const glm::vec3 nl = glm::normalize(glm::cross(b - a, c - a));
    const glm::vec3 to = q - s.p;
    const float d2 = glm::dot(to, to);
    if (d2 <= 0.0f) continue;
    const float dist = std::sqrt(d2);
    const glm::vec3 wi = to / dist;
    const float cos_l = glm::dot(nl, -wi);
    if (cos_l <= 0.0f) continue;
    if (part == 1) *touched = true;
    const glm::vec3 le = scene_.materials[mesh.material].emission;
    float pdf_bsdf;
    const glm::vec3 fc = eval(wi, &pdf_bsdf);
    if (max_component(fc * le) <= 0.0f) continue;
    const float pdf_light = emitter_pdf(set, dist, cos_l);
    const float tmax = dist * (1.0f - 1e-4f) - ray_epsilon(s.p) - ray_epsilon(q);
    if (tmax <= 0.0f || occluded(origin, wi, tmax, combined, touched)) continue;
    sum += fc * le * (mis_balance(pdf_light, pdf_bsdf) / pdf_light);
  }
  return sum;
}

glm::vec3 Integrator::trace(glm::vec3 o, glm::vec3 d, const SampleRng& rng, bool combined, bool* touched) const {
  glm::vec3 radiance(0.0f), throughput(1.0f);
  float prev_pdf = 0.0f;
  bool prev_delta = true;  // the camera ray counts as a delta lobe: emitters seen directly get full weight
  for (int bounce = 0;; ++bounce) {
    const Hit hit = intersect(o, d, kInf, combined);
    if (!hit.found) {
      if (scene_.environment.present()) {
        const float w = prev_delta ? 1.0f : mis_balance(prev_pdf, scene_.environment.pdf(d));
        radiance += throughput * scene_.environment.radiance(d) * w;
      }
      break;
    }
    if (hit.is_virtual) *touched = true;
    const SurfacePoint s = surface(hit, o, d);
    const RefMaterial& m = *s.material;
    const float cos_front = glm::dot(s.ng, -d);
    if (max_component(m.emission) > 0.0f && cos_front > 0.0f) {
      const EmitterSet& set = hit.is_virtual ? scene_.virtual_emitters : scene_.real_emitters;
      const float w = prev_delta ? 1.0f : mis_balance(prev_pdf, emitter_pdf(set, hit.t, cos_front));
      radiance += throughput * m.emission * w;
    }
    if (bounce > settings_.max_depth) break;  // emitters reached by the last bounce still count

    const ShadingPoint sp = shading(s);
    const glm::vec3 wo = -d;
    BsdfSample bs;
    glm::vec3 n_next;  // side the next ray leaves from
    if (sp.type == MaterialType::Glass) {
      const Frame3 frame(s.ns);
      if (!bsdf_sample_local(sp, frame.to_local(wo), rng.uniform(dims::at(bounce, dims::kBsdfLobe)),
                             rng.uniform2(dims::at(bounce, dims::kBsdfDir)), bs))
        break;
      bs.wi = glm::normalize(frame.to_world(bs.wi));
      n_next = glm::dot(bs.wi, s.ng) >= 0.0f ? s.ng : -s.ng;
    } else {
      const bool front = cos_front >= 0.0f;
      const glm::vec3 n_facing = front ? s.ng : -s.ng;
      const glm::vec3 ns_facing = front ? s.ns : -s.ns;
      const Frame3 frame(ns_facing);
      const glm::vec3 wo_local = frame.to_local(wo);
      if (!sp.is_delta())
        radiance += throughput * direct_light(s, sp, frame, wo_local, n_facing, rng, bounce, combined, touched);
      if (!bsdf_sample_local(sp, wo_local, rng.uniform(dims::at(bounce, dims::kBsdfLobe)),
                             rng.uniform2(dims::at(bounce, dims::kBsdfDir)), bs))
        break;
      bs.wi = glm::normalize(frame.to_world(bs.wi));
      if (glm::dot(bs.wi, n_facing) <= 0.0f) break;  // shading normal sent the ray into the surface
      n_next = n_facing;
    }
    throughput *= bs.weight;
    if (!finite3(throughput) || max_component(throughput) <= 0.0f) break;
    prev_pdf = bs.pdf;
    prev_delta = bs.delta;
    o = s.p + n_next * ray_epsilon(s.p);
    d = bs.wi;
    if (bounce + 1 >= settings_.rr_depth) {
      const float q = std::min(0.95f, max_component(throughput));
      if (rng.uniform(dims::at(bounce, dims::kRoulette)) >= q) break;
      throughput /= q;
    }
  }
  return radiance;
}

size_t Integrator::render_pixel(int x, int y, RenderOutput& out) const {
  const int w = camera_.image_width();
  const size_t index = size_t(y) * w + x;
  const uint64_t pixel_key = hash_key(frame_key_, index);
  size_t dropped = 0;

  // Pixel-centre ray: depth, incidence and virtual mask, no jitter. Integer pixel coordinates
  // are pixel centres (OpenCV; shaders/shared/mrgi_shared.h project_pinhole).
  glm::vec3 o, d, dc;
  if (camera_ray(x, y, &o, &d, &dc)) {
    const Hit real_hit = intersect(o, d, kInf, false);
    if (real_hit.found) {
      const SurfacePoint s = surface(real_hit, o, d);
      out.depth_z[index] = real_hit.t * dc.z;
      out.cos_incidence[index] = std::abs(glm::dot(s.ng, d));
    }
    if (!settings_.real_only) {
      const Hit hit = intersect(o, d, kInf, true);
      out.virtual_mask.data[index] = hit.found && hit.is_virtual ? 255 : 0;
    }
  }

  glm::dvec3 sum_real(0.0), sum_combined(0.0);
  for (int sample = 0; sample < settings_.spp; ++sample) {
    const SampleRng rng{hash_key(pixel_key, uint64_t(sample))};
    const glm::vec2 j = rng.uniform2(dims::kPixelJitter);
    if (!camera_ray(x - 0.5 + j.x, y - 0.5 + j.y, &o, &d, &dc)) continue;
    glm::vec3 real(0.0f), combined(0.0f);
    if (settings_.real_only) {
      bool unused = false;
      real = trace(o, d, rng, false, &unused);
    } else {
      bool touched = false;
      combined = trace(o, d, rng, true, &touched);
      real = touched ? trace(o, d, rng, false, &touched) : combined;
    }
    if (!finite3(real) || !finite3(combined)) {
      ++dropped;
      continue;
    }
    sum_real += glm::dvec3(real);
    sum_combined += glm::dvec3(combined);
  }
  const double inv = 1.0 / settings_.spp;
  for (int c = 0; c < 3; ++c) {
    out.real.data[index * 3 + c] = float(sum_real[c] * inv);
    if (!settings_.real_only) out.combined.data[index * 3 + c] = float(sum_combined[c] * inv);
  }
  return dropped;
}

size_t Integrator::trace_light_paths(size_t light_index, uint64_t first, uint64_t count, uint64_t count_total,
                                     bool combined, std::vector<double>& accum) const {
  const RefLight& light = scene_.lights[light_index];
  if (light.type == RefLightType::Directional || (light.is_virtual && !combined) || camera_.model != RefCamera::Model::Pinhole)
    return 0;
  // The cone of directions from the lamp that holds every delta-material mesh (paths whose first
  // vertex is not delta are the pixel estimator's: leaving them out of the emission keeps the
  // estimate unbiased and puts every photon where it counts).
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  bool any = false;
  for (int part = 0; part < (combined ? 2 : 1); ++part)
    for (const RefMesh& m : part == 0 ? scene_.real_meshes : scene_.virtual_meshes) {
      const MaterialType t = scene_.materials[m.material].type;
      if (t != MaterialType::Mirror && t != MaterialType::Glass) continue;
      for (const glm::vec3& p : m.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        any = true;
      }
    }
  if (!any) return 0;
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo);
  const glm::vec3 to = centre - light.position;
  const float dist = glm::length(to);
  const glm::vec3 axis = dist > 0.0f ? to / dist : glm::vec3(0.0f, -1.0f, 0.0f);
  const float cos_max = dist > radius ? std::sqrt(std::max(0.0f, 1.0f - radius * radius / (dist * dist))) : -1.0f;
  const float cone_sr = 2.0f * kPi * (1.0f - cos_max);
  const Frame3 cone_frame(axis);
  const Intrinsics& k = camera_.pinhole;
  const int w = k.width, h = k.height;
  const glm::mat3 world_to_cam = glm::transpose(cam_rot_);
  const uint64_t light_key = hash_key(hash_key(frame_key_, 0x6C74ull), light_index);
  size_t dropped = 0;
  for (uint64_t i = first; i < first + count; ++i) {
    const SampleRng rng{hash_key(light_key, i)};
    const glm::vec2 u = rng.uniform2(dims::kPixelJitter);
    const float cos_t = 1.0f - u.x * (1.0f - cos_max), sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
    const float phi = 2.0f * kPi * u.y;
    glm::vec3 d = glm::normalize(cone_frame.to_world(glm::vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t)));
    glm::vec3 power = light.intensity * (cone_sr / float(count_total));
    if (light.type == RefLightType::Spot)
      power *= spot_falloff(glm::dot(d, glm::normalize(light.direction)), light.cos_outer, light.cos_inner);
    if (max_component(power) <= 0.0f) continue;
    glm::vec3 o = light.position;
    bool after_delta = false;
    for (int bounce = 0; bounce <= settings_.max_depth; ++bounce) {
      const Hit hit = intersect(o, d, kInf, combined);
      if (!hit.found) break;
      const SurfacePoint s = surface(hit, o, d);
      const ShadingPoint sp = shading(s);
      if (bounce == 0 && !sp.is_delta()) break;  // the pixel estimator's path
      const glm::vec3 wi = -d;                    // towards where the light came from
      const bool front = glm::dot(s.ng, wi) >= 0.0f;
      const glm::vec3 n_facing = front ? s.ng : -s.ng;
      const glm::vec3 ns_facing = front ? s.ns : -s.ns;
      if (!sp.is_delta() && after_delta) {
        // Connect to the camera: pixel j gets power f cos_o / (d^2 Omega_j), Omega_j the pixel's
        // solid angle cos^3 / (fx fy) (a box filter over the pixel, as the jittered camera rays).
        const glm::vec3 to_cam = cam_pos_ - s.p;
        const float d2 = glm::dot(to_cam, to_cam);
        const glm::vec3 wo = to_cam / std::sqrt(d2);
        const glm::vec3 c = world_to_cam * (-to_cam);
        if (c.z > 0.0f && glm::dot(wo, n_facing) > 0.0f) {
          const double px = k.fx * c.x / c.z + k.cx, py = k.fy * c.y / c.z + k.cy;
          const int x = int(std::floor(px + 0.5)), y = int(std::floor(py + 0.5));
          if (x >= 0 && y >= 0 && x < w && y < h) {
            const Frame3 frame(ns_facing);
            float pdf;
            const glm::vec3 f = bsdf_eval_local(sp, frame.to_local(wo), frame.to_local(wi), &pdf);
            const float cos_c = c.z / std::sqrt(d2);
            const float cos_o = std::max(glm::dot(frame.to_local(wo), glm::vec3(0.0f, 0.0f, 1.0f)), 0.0f);
            const float omega = cos_c * cos_c * cos_c / float(k.fx * k.fy);
            const glm::vec3 value = power * f * cos_o / (d2 * omega);
            bool unused = false;
            if (max_component(value) > 0.0f &&
                !occluded(s.p + n_facing * ray_epsilon(s.p), wo, std::sqrt(d2) * (1.0f - 1e-4f), combined, &unused)) {
              if (!finite3(value)) {
                ++dropped;
              } else {
                const size_t at = (size_t(y) * size_t(w) + size_t(x)) * 3;
                for (int ch = 0; ch < 3; ++ch) accum[at + size_t(ch)] += double(value[ch]);
              }
            }
          }
        }
      }
      BsdfSample bs;
      glm::vec3 n_next;
      if (sp.type == MaterialType::Glass) {
        const Frame3 frame(s.ns);
        if (!bsdf_sample_local(sp, frame.to_local(wi), rng.uniform(dims::at(bounce, dims::kBsdfLobe)),
                               rng.uniform2(dims::at(bounce, dims::kBsdfDir)), bs))
          break;
        bs.wi = glm::normalize(frame.to_world(bs.wi));
        n_next = glm::dot(bs.wi, s.ng) >= 0.0f ? s.ng : -s.ng;
      } else {
        const Frame3 frame(ns_facing);
        if (!bsdf_sample_local(sp, frame.to_local(wi), rng.uniform(dims::at(bounce, dims::kBsdfLobe)),
                               rng.uniform2(dims::at(bounce, dims::kBsdfDir)), bs))
          break;
        bs.wi = glm::normalize(frame.to_world(bs.wi));
        if (glm::dot(bs.wi, n_facing) <= 0.0f) break;
        n_next = n_facing;
      }
      // Sampling from the light side with the BSDF's own (camera-side) sampler: the materials'
      // weights f |cos| / pdf hold both ways for the delta lobes and the Lambertian base; the
      // glossy lobe's are not exactly adjoint (a small bias in caustics' further bounces only).
      power *= bs.weight;
      if (!finite3(power) || max_component(power) <= 0.0f) break;
      after_delta = after_delta || sp.is_delta();
      o = s.p + n_next * ray_epsilon(s.p);
      d = bs.wi;
      if (bounce + 1 >= settings_.rr_depth) {
        const float q = std::min(0.95f, max_component(bs.weight));
        if (rng.uniform(dims::at(bounce, dims::kRoulette)) >= q) break;
        power /= q;
      }
    }
  }
  return dropped;
}

}  // namespace mrgi::reference
