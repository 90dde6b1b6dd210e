// scene.json v1 (docs/DESIGN.md). The schema, key by key:
//   version          required, 1
//   virtual_objects  [{gltf (required), position [3], rotation [x,y,z,w], scale number|[3]}]
//   lights           [{type point|spot|directional (required), real bool (required),
//                      position [3] (point, spot: required), direction [3] (spot, directional:
//                      required, non-zero, normalised on load), color [3] >= 0 (default 1),
//                      intensity >= 0 (default 1), inner_angle_deg / outer_angle_deg (spot only,
//                      0 <= inner <= outer < 90, defaults 30 / 45)}]
//   environment      {real bool (default true), image path | from_env_camera true (exactly one),
//                     intensity >= 0 (default 1), rotation [x,y,z,w]}
//   real_geometry    [{gltf (required), position, rotation, scale,
//                      material {base_color [3] in [0,1], roughness, metallic in [0,1]}}]
//   real_materials   [{min [3], max [3] (required, world metres, min <= max per axis),
//                      roughness (default 1), metallic (default 0), both in [0,1]}]
// A key that has no meaning for a light's type (a directional light's position, a point light's
// cone angles) is refused rather than ignored: it is almost always a mistake in the type.
#include <cmath>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "image/file_io.h"
#include "mrgi/json_reader.h"
#include "mrgi/scene.h"

namespace mrgi {

namespace fs = std::filesystem;

Placement placement_at(const std::vector<PoseKey>& motion, double t) {
  if (t <= motion.front().time_s) return motion.front().placement;
  if (t >= motion.back().time_s) return motion.back().placement;
  size_t i = 1;
  while (motion[i].time_s < t) ++i;
  const PoseKey& a = motion[i - 1];
  const PoseKey& b = motion[i];
  const float f = float((t - a.time_s) / (b.time_s - a.time_s));
  Placement p;
  p.position = glm::mix(a.placement.position, b.placement.position, f);
  p.scale = glm::mix(a.placement.scale, b.placement.scale, f);
  p.rotation = glm::normalize(glm::slerp(glm::normalize(a.placement.rotation), glm::normalize(b.placement.rotation), f));
  return p;
}

LightDesc lamp_at(const LightDesc& lamp, double t) {
  const std::vector<LampKey>& m = lamp.motion;
  size_t i = 1;
  while (i < m.size() && m[i].time_s < t) ++i;
  const LampKey& a = t <= m.front().time_s ? m.front() : t >= m.back().time_s ? m.back() : m[i - 1];
  const LampKey& b = t <= m.front().time_s ? m.front() : t >= m.back().time_s ? m.back() : m[i];
  const float f = b.time_s > a.time_s ? float((t - a.time_s) / (b.time_s - a.time_s)) : 0.0f;
  LightDesc out;  // field by field: the motion is not copied
  out.type = lamp.type;
  out.real = lamp.real;
  out.color = lamp.color;
  out.inner_angle_deg = lamp.inner_angle_deg;
  out.outer_angle_deg = lamp.outer_angle_deg;
  out.position = glm::mix(a.position, b.position, f);
  const glm::vec3 d = glm::mix(a.direction, b.direction, f);
  out.direction = glm::length(d) > 1e-6f ? glm::normalize(d) : a.direction;
  out.intensity = glm::mix(a.intensity, b.intensity, f);
  return out;
}

glm::mat4 Placement::matrix() const {
  const glm::mat4 t = glm::translate(glm::mat4(1.0f), position);
  const glm::mat4 r = glm::mat4_cast(glm::normalize(rotation));
  const glm::mat4 s = glm::scale(glm::mat4(1.0f), scale);
  return t * r * s;
}

namespace {

constexpr int kSceneVersion = 1;

Expected<std::string> resolve_existing_file(const JsonObject& obj, std::string_view key,
                                            const fs::path& base) {
  auto rel = obj.string(key);
  if (!rel) return rel.error();
  if (rel->empty()) return obj.error(key, "path must not be empty");
  const fs::path resolved = (base / *rel).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    return fail(ErrorKind::NotFound, obj.file() + ": " + obj.path_of(key) + ": file '" +
                                         resolved.string() + "' does not exist (paths are relative "
                                         "to the scene file's folder)");
  return resolved.string();
}

Expected<glm::vec3> read_scale(const JsonObject& obj) {
  if (!obj.has("scale")) return glm::vec3(1.0f);
  glm::dvec3 s;
  if (obj.json()["scale"].is_number()) {
    auto n = obj.number("scale");
    if (!n) return n.error();
    s = glm::dvec3(*n);
  } else {
    auto v = obj.vec3("scale");
    if (!v) return obj.error("scale", "must be a number (uniform) or an array of 3 numbers");
    s = *v;
  }
  if (s.x <= 0.0 || s.y <= 0.0 || s.z <= 0.0) return obj.error("scale", "must be positive");
  return glm::vec3(s);
}

Expected<Placement> read_placement(const JsonObject& obj) {
  Placement p;
  auto pos = obj.vec3("position", glm::dvec3(0.0));
  if (!pos) return pos.error();
  auto rot = obj.quat_xyzw("rotation", glm::dquat(1.0, 0.0, 0.0, 0.0));
  if (!rot) return rot.error();
  auto scale = read_scale(obj);
  if (!scale) return scale.error();
  p.position = glm::vec3(*pos);
  p.rotation = glm::quat(*rot);
  p.scale = *scale;
  return p;
}

Status check_range(const JsonObject& obj, std::string_view key, double v, double lo, double hi) {
  if (v < lo || v > hi)
    return obj.error(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                              std::to_string(v));
  return ok_status();
}

template <class T, class F>
Status read_list(const JsonObject& root, std::string_view key, std::vector<T>* out, F&& read_one) {
  if (!root.has(key)) return ok_status();
  auto items = root.objects(key);
  if (!items) return items.error();
  for (const JsonObject& item : *items) {
    auto v = read_one(item);
    if (!v) return v.error();
    out->push_back(std::move(*v));
  }
  return ok_status();
}

Expected<PoseKey> read_pose_key(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"time", "position", "rotation", "scale"}));
  PoseKey key;
  auto t = obj.number("time");
  if (!t) return t.error();
  if (!std::isfinite(*t)) return obj.error("time", "must be a finite number of seconds");
  key.time_s = *t;
  auto placement = read_placement(obj);
  if (!placement) return placement.error();
  key.placement = *placement;
  return key;
}

Expected<VirtualObjectDesc> read_virtual_object(const JsonObject& obj, const fs::path& base) {
  MRGI_TRY(obj.only_keys({"gltf", "position", "rotation", "scale", "motion"}));
  VirtualObjectDesc desc;
  auto gltf = resolve_existing_file(obj, "gltf", base);
  if (!gltf) return gltf.error();
  desc.gltf = *gltf;
  auto placement = read_placement(obj);
  if (!placement) return placement.error();
  desc.placement = *placement;
  MRGI_TRY(read_list(obj, "motion", &desc.motion, [](const JsonObject& o) { return read_pose_key(o); }));
  for (size_t i = 1; i < desc.motion.size(); ++i)
    if (!(desc.motion[i].time_s > desc.motion[i - 1].time_s))
      return obj.error("motion", "key times must increase strictly (key " + std::to_string(i) + " at " +
                                     std::to_string(desc.motion[i].time_s) + " s after " +
                                     std::to_string(desc.motion[i - 1].time_s) + " s)");
  return desc;
}

// A lamp's keyframe: "time", and any of "position", "direction", "intensity" (the lamp's own
// where a key leaves one out).
Expected<LampKey> read_lamp_key(const JsonObject& obj, const LightDesc& lamp) {
  MRGI_TRY(obj.only_keys({"time", "position", "direction", "intensity"}));
  LampKey key;
  auto t = obj.number("time");
  if (!t) return t.error();
  if (!std::isfinite(*t)) return obj.error("time", "must be a finite number of seconds");
  key.time_s = *t;
  if (lamp.type == LightType::Directional && obj.has("position"))
    return obj.error("position", "a directional light has no position (remove the key)");
  if (lamp.type == LightType::Point && obj.has("direction"))
    return obj.error("direction", "a point light has no direction (remove the key)");
  auto pos = obj.vec3("position", glm::dvec3(lamp.position));
  if (!pos) return pos.error();
  key.position = glm::vec3(*pos);
  auto dir = obj.vec3("direction", glm::dvec3(lamp.direction));
  if (!dir) return dir.error();
  const double len = glm::length(*dir);
  if (!(len > 1e-9)) return obj.error("direction", "must be non-zero");
  key.direction = glm::vec3(*dir / len);
  auto intensity = obj.number("intensity", double(lamp.intensity));
  if (!intensity) return intensity.error();
  if (!(*intensity >= 0.0) || !std::isfinite(*intensity)) return obj.error("intensity", "must be a finite number >= 0");
  key.intensity = float(*intensity);
  return key;
}

Expected<LightDesc> read_light(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"type", "real", "position", "direction", "color", "intensity",
                          "inner_angle_deg", "outer_angle_deg", "motion"}));
  LightDesc light;
  auto type = obj.string("type");
  if (!type) return type.error();
  if (*type == "point") light.type = LightType::Point;
  else if (*type == "spot") light.type = LightType::Spot;
  else if (*type == "directional") light.type = LightType::Directional;
  else return obj.error("type", "must be \"point\", \"spot\" or \"directional\", got \"" + *type + "\"");

  auto real = obj.boolean("real");
  if (!real) return real.error();
  light.real = *real;

  const bool positional = light.type != LightType::Directional;
  const bool directed = light.type != LightType::Point;
  if (positional) {
    auto pos = obj.vec3("position");
    if (!pos) return pos.error();
    light.position = glm::vec3(*pos);
  } else if (obj.has("position")) {
    return obj.error("position", "a directional light has no position (remove the key)");
  }
  if (directed) {
    auto dir = obj.vec3("direction");
    if (!dir) return dir.error();
    const double len = glm::length(*dir);
    if (!(len > 1e-9)) return obj.error("direction", "must be non-zero");
    // Keep a unit vector as given so a written scene reads back bit-identical.
    light.direction = std::abs(len - 1.0) < 1e-6 ? glm::vec3(*dir) : glm::vec3(*dir / len);
  } else if (obj.has("direction")) {
    return obj.error("direction", "a point light has no direction (remove the key, or use \"spot\")");
  }
  auto color = obj.vec3("color", glm::dvec3(1.0));
  if (!color) return color.error();
  if (color->x < 0 || color->y < 0 || color->z < 0) return obj.error("color", "components must be >= 0");
  light.color = glm::vec3(*color);
  auto intensity = obj.number("intensity", 1.0);
  if (!intensity) return intensity.error();
  if (*intensity < 0) return obj.error("intensity", "must be >= 0");
  light.intensity = float(*intensity);

  if (light.type == LightType::Spot) {
    auto inner = obj.number("inner_angle_deg", 30.0);
    if (!inner) return inner.error();
    auto outer = obj.number("outer_angle_deg", 45.0);
    if (!outer) return outer.error();
    if (*inner < 0) return obj.error("inner_angle_deg", "must be >= 0");
    if (!(*outer > 0 && *outer < 90))
      return obj.error("outer_angle_deg", "spot cone half-angle must be in (0, 90) degrees, got " +
                                              std::to_string(*outer));
    if (*inner > *outer)
      return obj.error("inner_angle_deg", "must not exceed outer_angle_deg (" +
                                              std::to_string(*inner) + " > " + std::to_string(*outer) + ")");
    light.inner_angle_deg = float(*inner);
    light.outer_angle_deg = float(*outer);
  } else {
    for (std::string_view key : {"inner_angle_deg", "outer_angle_deg"})
      if (obj.has(key)) return obj.error(key, "cone angles apply to spot lights only");
  }
  MRGI_TRY(read_list(obj, "motion", &light.motion, [&](const JsonObject& o) { return read_lamp_key(o, light); }));
  for (size_t i = 1; i < light.motion.size(); ++i)
    if (!(light.motion[i].time_s > light.motion[i - 1].time_s))
      return obj.error("motion", "key times must increase strictly (key " + std::to_string(i) + " at " +
                                     std::to_string(light.motion[i].time_s) + " s after " +
                                     std::to_string(light.motion[i - 1].time_s) + " s)");
  return light;
}

Expected<EnvironmentDesc> read_environment(const JsonObject& obj, const fs::path& base) {
  MRGI_TRY(obj.only_keys({"real", "image", "from_env_camera", "intensity", "rotation"}));
  EnvironmentDesc env;
  env.present = true;
  auto real = obj.boolean("real", true);
  if (!real) return real.error();
  env.real = *real;
  auto from_camera = obj.boolean("from_env_camera", false);
  if (!from_camera) return from_camera.error();
  env.from_env_camera = *from_camera;
  if (obj.has("image") == env.from_env_camera)
    return obj.error(env.from_env_camera ? "image" : "from_env_camera",
                     "give exactly one of \"image\" (a path) or \"from_env_camera\": true");
  if (obj.has("image")) {
    auto image = resolve_existing_file(obj, "image", base);
    if (!image) return image.error();
    env.image = *image;
  }
  auto intensity = obj.number("intensity", 1.0);
  if (!intensity) return intensity.error();
  if (*intensity < 0) return obj.error("intensity", "must be >= 0");
  env.intensity = float(*intensity);
  auto rot = obj.quat_xyzw("rotation", glm::dquat(1.0, 0.0, 0.0, 0.0));
  if (!rot) return rot.error();
  env.rotation = glm::quat(*rot);
  return env;
}

Expected<RealGeometryDesc> read_real_geometry(const JsonObject& obj, const fs::path& base) {
  MRGI_TRY(obj.only_keys({"gltf", "position", "rotation", "scale", "material"}));
  RealGeometryDesc desc;
  auto gltf = resolve_existing_file(obj, "gltf", base);
  if (!gltf) return gltf.error();
  desc.gltf = *gltf;
  auto placement = read_placement(obj);
  if (!placement) return placement.error();
  desc.placement = *placement;
  if (obj.has("material")) {
    auto mat = obj.object("material");
    if (!mat) return mat.error();
    MRGI_TRY(mat->only_keys({"base_color", "roughness", "metallic"}));
    desc.has_material_hint = true;
    auto color = mat->vec3("base_color", glm::dvec3(desc.material.base_color));
    if (!color) return color.error();
    for (int c = 0; c < 3; ++c) MRGI_TRY(check_range(*mat, "base_color", (*color)[c], 0.0, 1.0));
    auto roughness = mat->number("roughness", desc.material.roughness);
    if (!roughness) return roughness.error();
    MRGI_TRY(check_range(*mat, "roughness", *roughness, 0.0, 1.0));
    auto metallic = mat->number("metallic", desc.material.metallic);
    if (!metallic) return metallic.error();
    MRGI_TRY(check_range(*mat, "metallic", *metallic, 0.0, 1.0));
    desc.material.base_color = glm::vec3(*color);
    desc.material.roughness = float(*roughness);
    desc.material.metallic = float(*metallic);
  }
  return desc;
}

Expected<RealMaterialRegion> read_real_material(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"min", "max", "roughness", "metallic"}));
  RealMaterialRegion r;
  auto lo = obj.vec3("min");
  if (!lo) return lo.error();
  auto hi = obj.vec3("max");
  if (!hi) return hi.error();
  for (int c = 0; c < 3; ++c)
    if (!((*lo)[c] <= (*hi)[c])) return obj.error("max", "must be >= min on every axis (an axis-aligned box)");
  auto roughness = obj.number("roughness", 1.0);
  if (!roughness) return roughness.error();
  MRGI_TRY(check_range(obj, "roughness", *roughness, 0.0, 1.0));
  auto metallic = obj.number("metallic", 0.0);
  if (!metallic) return metallic.error();
  MRGI_TRY(check_range(obj, "metallic", *metallic, 0.0, 1.0));
  r.min = glm::vec3(*lo);
  r.max = glm::vec3(*hi);
  r.roughness = float(*roughness);
  r.metallic = float(*metallic);
  return r;
}

std::string relative_to(const std::string& path, const fs::path& folder) {
  std::error_code ec;
  const fs::path abs = fs::absolute(path, ec);
  const fs::path base = fs::absolute(folder, ec);
  const fs::path rel = abs.lexically_relative(base);
  return rel.empty() ? abs.generic_string() : rel.generic_string();
}

nlohmann::json placement_json(const Placement& p) {
  nlohmann::json j;
  j["position"] = {p.position.x, p.position.y, p.position.z};
  j["rotation"] = {p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w};
  j["scale"] = {p.scale.x, p.scale.y, p.scale.z};
  return j;
}

const char* light_type_name(LightType t) {
  switch (t) {
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
  }
  return "point";
}

}  // namespace

Expected<SceneDesc> load_scene_json(const std::string& path) {
  auto json = load_json_file(path);
  if (!json) return json.error();
  auto root = JsonObject::from(*json, path, "");
  if (!root) return root.error();
  MRGI_TRY(root->only_keys({"version", "virtual_objects", "lights", "environment", "real_geometry", "real_materials"}));
  auto version = root->integer("version");
  if (!version) return version.error();
  if (*version != kSceneVersion)
    return root->error("version", "unsupported scene.json version " + std::to_string(*version) +
                                      " (this build reads version 1)");
  const fs::path base = fs::path(path).parent_path();
  SceneDesc scene;
  scene.path = path;
  MRGI_TRY(read_list(*root, "virtual_objects", &scene.virtual_objects,
                     [&](const JsonObject& o) { return read_virtual_object(o, base); }));
  MRGI_TRY(read_list(*root, "lights", &scene.lights, [](const JsonObject& o) { return read_light(o); }));
  if (root->has("environment")) {
    auto env_obj = root->object("environment");
    if (!env_obj) return env_obj.error();
    auto env = read_environment(*env_obj, base);
    if (!env) return env.error();
    scene.environment = *env;
  }
  MRGI_TRY(read_list(*root, "real_geometry", &scene.real_geometry,
                     [&](const JsonObject& o) { return read_real_geometry(o, base); }));
  MRGI_TRY(read_list(*root, "real_materials", &scene.real_materials,
                     [](const JsonObject& o) { return read_real_material(o); }));
  return scene;
}

Status write_scene_json(const std::string& path, const SceneDesc& scene) {
  const fs::path folder = fs::path(path).parent_path();
  nlohmann::json j;
  j["version"] = kSceneVersion;
  j["virtual_objects"] = nlohmann::json::array();
  for (const auto& o : scene.virtual_objects) {
    nlohmann::json e = placement_json(o.placement);
    e["gltf"] = relative_to(o.gltf, folder);
    if (!o.motion.empty()) {
      e["motion"] = nlohmann::json::array();
      for (const PoseKey& k : o.motion) {
        nlohmann::json key = placement_json(k.placement);
        key["time"] = k.time_s;
        e["motion"].push_back(key);
      }
    }
    j["virtual_objects"].push_back(e);
  }
  j["lights"] = nlohmann::json::array();
  for (const auto& l : scene.lights) {
    nlohmann::json e;
    e["type"] = light_type_name(l.type);
    e["real"] = l.real;
    if (l.type != LightType::Directional) e["position"] = {l.position.x, l.position.y, l.position.z};
    if (l.type != LightType::Point) e["direction"] = {l.direction.x, l.direction.y, l.direction.z};
    e["color"] = {l.color.x, l.color.y, l.color.z};
    e["intensity"] = l.intensity;
    if (l.type == LightType::Spot) {
      e["inner_angle_deg"] = l.inner_angle_deg;
      e["outer_angle_deg"] = l.outer_angle_deg;
    }
    if (!l.motion.empty()) {
      e["motion"] = nlohmann::json::array();
      for (const LampKey& k : l.motion) {
        nlohmann::json key;
        key["time"] = k.time_s;
        if (l.type != LightType::Directional) key["position"] = {k.position.x, k.position.y, k.position.z};
        if (l.type != LightType::Point) key["direction"] = {k.direction.x, k.direction.y, k.direction.z};
        key["intensity"] = k.intensity;
        e["motion"].push_back(key);
      }
    }
    j["lights"].push_back(e);
  }
  if (scene.environment.present) {
    const auto& env = scene.environment;
    nlohmann::json e;
    e["real"] = env.real;
    if (env.from_env_camera) e["from_env_camera"] = true;
    else e["image"] = relative_to(env.image, folder);
    e["intensity"] = env.intensity;
    e["rotation"] = {env.rotation.x, env.rotation.y, env.rotation.z, env.rotation.w};
    j["environment"] = e;
  }
  j["real_geometry"] = nlohmann::json::array();
  for (const auto& g : scene.real_geometry) {
    nlohmann::json e = placement_json(g.placement);
    e["gltf"] = relative_to(g.gltf, folder);
    if (g.has_material_hint) {
      const auto& m = g.material;
      e["material"] = {{"base_color", {m.base_color.x, m.base_color.y, m.base_color.z}},
                       {"roughness", m.roughness},
                       {"metallic", m.metallic}};
    }
    j["real_geometry"].push_back(e);
  }
  if (!scene.real_materials.empty()) {
    j["real_materials"] = nlohmann::json::array();
    for (const RealMaterialRegion& r : scene.real_materials)
      j["real_materials"].push_back({{"min", {r.min.x, r.min.y, r.min.z}},
                                     {"max", {r.max.x, r.max.y, r.max.z}},
                                     {"roughness", r.roughness},
                                     {"metallic", r.metallic}});
  }
  return write_text_file(path, j.dump(2) + "\n");
}

}  // namespace mrgi
