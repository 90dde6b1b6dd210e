#include "synthetic_scene.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mrgi/image.h"
#include "../../shaders/shared/mrgi_shared.h"

namespace mrgi::test {
namespace {

// Unit cube x, z in [-0.5, 0.5], y in [0, 1] (resting on y = 0), 24 vertices with face normals.
void write_cube_gltf(const std::string& folder, const glm::vec3& base, const glm::vec3& emission, float metallic,
                     float roughness, float transmission) {
  std::vector<float> pos, nrm;
  std::vector<uint16_t> idx;
  const glm::vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& n : normals) {
    const glm::vec3 a = glm::abs(n).x > 0.5f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 b = glm::cross(n, a);
    const uint16_t first = uint16_t(pos.size() / 3);
    const float s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& c : s) {
      glm::vec3 p = 0.5f * (n + c[0] * a + c[1] * b) + glm::vec3(0.0f, 0.5f, 0.0f);
      pos.insert(pos.end(), {p.x, p.y, p.z});
      nrm.insert(nrm.end(), {n.x, n.y, n.z});
    }
    idx.insert(idx.end(), {first, uint16_t(first + 1), uint16_t(first + 2), first,
                           uint16_t(first + 2), uint16_t(first + 3)});
  }
  nlohmann::json extensions = nlohmann::json::object();
  if (transmission > 0.0f) extensions["KHR_materials_transmission"] = {{"transmissionFactor", transmission}};
  std::ofstream bin(folder + "/cube.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(pos.data()), std::streamsize(pos.size() * 4));
  bin.write(reinterpret_cast<const char*>(nrm.data()), std::streamsize(nrm.size() * 4));
  bin.write(reinterpret_cast<const char*>(idx.data()), std::streamsize(idx.size() * 2));
  bin.close();
  const size_t pbytes = pos.size() * 4, ibytes = idx.size() * 2;
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}},
                                    {"indices", 2}, {"material", 0}}}}}}},
      {"materials", {{{"pbrMetallicRoughness", {{"baseColorFactor", {base.x, base.y, base.z, 1.0}},
                                                {"metallicFactor", metallic},
                                                {"roughnessFactor", roughness}}},
                      {"emissiveFactor", {emission.x, emission.y, emission.z}},
                      {"extensions", extensions}}}},
      {"buffers", {{{"uri", "cube.bin"}, {"byteLength", 2 * pbytes + ibytes}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", pbytes}},
                       {{"buffer", 0}, {"byteOffset", pbytes}, {"byteLength", pbytes}},
                       {{"buffer", 0}, {"byteOffset", 2 * pbytes}, {"byteLength", ibytes}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 24}, {"type", "VEC3"},
                      {"min", {-0.5, 0.0, -0.5}}, {"max", {0.5, 1.0, 0.5}}},
                     {{"bufferView", 1}, {"componentType", 5126}, {"count", 24}, {"type", "VEC3"}},
                     {{"bufferView", 2}, {"componentType", 5123}, {"count", 36}, {"type", "SCALAR"}}}}};
  std::ofstream(folder + "/cube.gltf") << j.dump(2);
}

}  // namespace

std::optional<float> Box::hit(const glm::vec3& p, const glm::vec3& d, float t_min, float t_max) const {
  float t0 = t_min, t1 = t_max;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12f) {
      if (p[i] < lo[i] || p[i] > hi[i]) return std::nullopt;
      continue;
    }
    float a = (lo[i] - p[i]) / d[i], b = (hi[i] - p[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return std::nullopt;
  }
  return t0;
}

glm::vec3 Box::normal_at(const glm::vec3& q) const {
  glm::vec3 best(0.0f, 1.0f, 0.0f);
  float dist = 1e30f;
  for (int i = 0; i < 3; ++i) {
    glm::vec3 n(0.0f);
    if (std::abs(q[i] - lo[i]) < dist) { dist = std::abs(q[i] - lo[i]); n[i] = -1.0f; best = n; }
    n = glm::vec3(0.0f);
    if (std::abs(q[i] - hi[i]) < dist) { dist = std::abs(q[i] - hi[i]); n[i] = 1.0f; best = n; }
  }
  return best;
}

SyntheticScene SyntheticScene::create(const std::string& folder, const glm::vec3& emission,
                                      const glm::vec3& base, float metallic, float roughness, float transmission) {
  SyntheticScene s;
  s.intrinsics.width = 64;
  s.intrinsics.height = 48;
  s.intrinsics.fx = s.intrinsics.fy = 40.0;
  s.intrinsics.cx = 31.5;
  s.intrinsics.cy = 23.5;
  // Camera axes in world: x -> +x, y (image down) -> +z, z (forward) -> -y.
  glm::dmat3 r(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
  s.pose.rotation = glm::quat_cast(r);
  s.pose.translation = glm::dvec3(0.0, 2.0, 0.0);
  s.real_box = {{-0.2f, 0.0f, 0.4f}, {0.2f, 0.4f, 0.8f}};

  s.virtual_base = base;
  write_cube_gltf(folder, s.virtual_base, emission, metallic, roughness, transmission);
  // C1: a virtual box whose shadow falls on open floor; C2: a thin virtual plate floating above
  // the real box, whose shadow covers part of the real box's own shadow (DIR Fig. 5).
  const Placement places[2] = {
      {glm::vec3(0.0f, 0.0f, -0.6f), glm::quat(1, 0, 0, 0), glm::vec3(0.4f, 0.4f, 0.4f)},
      {glm::vec3(0.0f, 0.55f, 0.6f), glm::quat(1, 0, 0, 0), glm::vec3(0.6f, 0.05f, 0.6f)}};
  for (const Placement& p : places) {
    s.scene.virtual_objects.push_back({folder + "/cube.gltf", p});
    s.virtual_boxes.push_back({p.position + glm::vec3(-0.5f, 0.0f, -0.5f) * p.scale,
                               p.position + glm::vec3(0.5f, 1.0f, 0.5f) * p.scale});
  }
  s.lamp.type = LightType::Spot;
  s.lamp.real = true;
  s.lamp.position = glm::vec3(-1.2f, 1.2f, 0.0f);
  s.lamp.direction = glm::normalize(glm::vec3(0.3f, 0.0f, 0.0f) - s.lamp.position);
  s.lamp.color = glm::vec3(1.0f);
  s.lamp.intensity = 4.0f;
  s.lamp.inner_angle_deg = 55.0f;
  s.lamp.outer_angle_deg = 65.0f;
  s.scene.lights.push_back(s.lamp);

  // Uniform real environment: its mean is the constant ambient the baseline adds.
  const uint8_t level = uint8_t(std::lround(255.0f * shader::srgb_encode1(s.ambient)));
  ImageRGB8 env(16, 8, level);
  (void)write_png(folder + "/env.png", env);
  s.ambient = shader::srgb_decode1(float(level) / 255.0f);
  s.scene.environment.present = true;
  s.scene.environment.real = true;
  s.scene.environment.image = folder + "/env.png";
  s.scene.path = folder + "/scene.json";
  return s;
}

CameraSetup SyntheticScene::cameras() const { return {intrinsics, intrinsics, depth_scale, exposure}; }

SurfaceHit SyntheticScene::trace(int u, int v, bool with_virtual) const {
  const glm::dmat4 c2w = pose.matrix();
  const glm::vec3 dir_cam((u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy, 1.0);
  const glm::vec3 o = glm::vec3(c2w[3]);
  const glm::vec3 d = glm::vec3(glm::dmat3(c2w) * glm::dvec3(dir_cam));
  SurfaceHit best;
  float t_best = 1e30f;
  if (d.y < 0.0f) {  // floor y = 0
    t_best = -o.y / d.y;
    best.kind = SurfaceKind::Floor;
    best.normal = glm::vec3(0, 1, 0);
  }
  if (auto t = real_box.hit(o, d, 1e-4f, t_best)) {
    t_best = *t;
    best.kind = SurfaceKind::RealBox;
    best.normal = real_box.normal_at(o + d * *t);
  }
  if (with_virtual) {
    for (size_t i = 0; i < virtual_boxes.size(); ++i) {
      if (auto t = virtual_boxes[i].hit(o, d, 1e-4f, t_best)) {
        t_best = *t;
        best.kind = SurfaceKind::Virtual;
        best.virtual_index = int(i);
        best.normal = virtual_boxes[i].normal_at(o + d * *t);
      }
    }
  }
  if (best.kind == SurfaceKind::None) return best;
  best.point = o + d * t_best;
  best.depth = t_best;  // dir_cam has z = 1, so t is the depth along the optical axis
  return best;
}

float SyntheticScene::direct(const glm::vec3& p, const glm::vec3& n) const {
  const glm::vec3 to = lamp.position - p;
  const float d2 = glm::dot(to, to);
  const glm::vec3 wi = to / std::sqrt(d2);
  const float cosang = glm::dot(n, wi);
  if (cosang <= 0.0f) return 0.0f;
  const float cone = shader::spot_falloff(glm::dot(lamp.direction, -wi),
                                          std::cos(glm::radians(lamp.outer_angle_deg)),
                                          std::cos(glm::radians(lamp.inner_angle_deg)));
  return lamp.intensity * cone * cosang / d2;
}

bool SyntheticScene::blocked_by_real_top(const glm::vec3& p) const {
  const glm::vec3 d = lamp.position - p;
  if (d.y <= 0.0f || p.y >= real_box.hi.y - 1e-4f) return false;
  const float t = (real_box.hi.y - p.y) / d.y;
  const glm::vec3 q = p + d * t;
  return t > 0.0f && t < 1.0f && q.x >= real_box.lo.x && q.x <= real_box.hi.x &&
         q.z >= real_box.lo.z && q.z <= real_box.hi.z;
}

bool SyntheticScene::blocked_by_real(const glm::vec3& p) const {
  return real_box.hit(p, lamp.position - p, 1e-3f, 1.0f).has_value();
}

bool SyntheticScene::blocked_by_virtual(const glm::vec3& p) const {
  for (const Box& b : virtual_boxes)
    if (b.hit(p, lamp.position - p, 1e-3f, 1.0f)) return true;
  return false;
}

InputFrame SyntheticScene::frame(int64_t index) const {
  InputFrame f;
  f.index = index;
  f.timestamp = double(index) / 30.0;
  f.color = ImageRGB8(intrinsics.width, intrinsics.height);
  f.depth = ImageU16(intrinsics.width, intrinsics.height);
  f.pose = pose;
  for (int v = 0; v < intrinsics.height; ++v) {
    for (int u = 0; u < intrinsics.width; ++u) {
      const SurfaceHit h = trace(u, v, false);
      if (h.kind == SurfaceKind::None) continue;
      const float albedo = h.kind == SurfaceKind::Floor ? floor_albedo : box_albedo;
      const glm::vec3 p = h.point + h.normal * 1e-4f;
      const float vis = blocked_by_real(p) ? 0.0f : 1.0f;
      const float radiance = albedo * ambient + albedo / shader::MRGI_PI * direct(p, h.normal) * vis;
      const float enc = shader::srgb_encode1(radiance * float(exposure));
      uint8_t* c = f.color.at(u, v);
      c[0] = c[1] = c[2] = uint8_t(std::lround(enc * 255.0f));
      f.depth.at(u, v)[0] = uint16_t(std::lround(h.depth * depth_scale));
    }
  }
  return f;
}

std::vector<FrameOutput> run_synthetic_frames(const SyntheticScene& scene, const RuntimeSettings& settings, int frames) {
  auto rt = create_runtime(settings, scene.cameras(), scene.scene);
  EXPECT_TRUE(rt.ok()) << rt.error().message;
  if (!rt.ok()) return {};
  return run_frames(**rt, scene, frames);
}

std::vector<FrameOutput> run_frames(Runtime& r, const SyntheticScene& scene, int frames,
                                    const std::function<void(int)>& before) {
  std::vector<FrameOutput> outs;
  for (int k = 0; k < frames; ++k) {
    if (before) before(k);
    auto o = r.process(scene.frame(k));
    EXPECT_TRUE(o.ok()) << o.error().message;
    if (!o.ok()) return outs;
    for (auto& x : *o) outs.push_back(std::move(x));
  }
  auto rest = r.flush();
  EXPECT_TRUE(rest.ok()) << rest.error().message;
  if (rest.ok())
    for (auto& x : *rest) outs.push_back(std::move(x));
  return outs;
}

std::unique_ptr<Runtime> cheapest_runtime(const std::string& technique, const SyntheticScene& scene,
                                          const RuntimeSettings& base) {
  RuntimeSettings settings = base;
  settings.technique = technique;
  settings.level = int(technique_levels(technique)->size()) - 1;
  auto rt = create_runtime(settings, scene.cameras(), scene.scene);
  EXPECT_TRUE(rt.ok()) << rt.error().message;
  return rt.ok() ? std::move(*rt) : nullptr;
}

double mask_iou(const FrameOutput& out, const SyntheticScene& scene) {
  int both = 0, either = 0;
  for (int v = 0; v < scene.intrinsics.height; ++v)
    for (int u = 0; u < scene.intrinsics.width; ++u) {
      const bool want = scene.trace(u, v, true).kind == SurfaceKind::Virtual;
      const bool got = out.virtual_mask.at(u, v)[0] != 0;
      both += want && got;
      either += want || got;
    }
  return either == 0 ? 1.0 : double(both) / double(either);
}

}  // namespace mrgi::test
