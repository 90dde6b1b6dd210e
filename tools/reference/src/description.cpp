// Strict reader of `mrgi synth` scene descriptions (format in mrgi/reference/description.h).
#include "mrgi/reference/description.h"

#include <cmath>
#include <filesystem>

#include "mrgi/json_reader.h"

namespace mrgi::reference {

namespace fs = std::filesystem;

namespace {

Expected<std::string> existing_file(const JsonObject& obj, std::string_view key, const fs::path& base) {
  auto rel = obj.string(key);
  if (!rel) return rel.error();
  if (rel->empty()) return obj.error(key, "must name a file");
  const fs::path p = (base / *rel).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(p, ec))
    return obj.error(key, "file '" + p.string() + "' does not exist (paths are relative to the description)");
  return p.string();
}

Expected<std::vector<double>> fixed_numbers(const JsonObject& obj, std::string_view key, size_t count) {
  const auto& v = obj.json().at(std::string(key));
  if (!v.is_array() || v.size() != count)
    return obj.error(key, "must be an array of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (const auto& e : v) {
    if (!e.is_number()) return obj.error(key, "must be an array of " + std::to_string(count) + " numbers");
    const double d = e.get<double>();
    if (!std::isfinite(d)) return obj.error(key, "must be finite");
    out.push_back(d);
  }
  return out;
}

Expected<double> positive(const JsonObject& obj, std::string_view key, double fallback) {
  auto v = obj.number(key, fallback);
  if (!v) return v.error();
  if (!(*v > 0.0)) return obj.error(key, "must be > 0");
  return *v;
}

Expected<double> non_negative(const JsonObject& obj, std::string_view key, double fallback) {
  auto v = obj.number(key, fallback);
  if (!v) return v.error();
  if (*v < 0.0) return obj.error(key, "must be >= 0");
  return *v;
}

Expected<glm::dvec3> colour(const JsonObject& obj, std::string_view key, glm::dvec3 fallback) {
  auto v = obj.vec3(key, fallback);
  if (!v) return v.error();
  if (v->x < 0.0 || v->y < 0.0 || v->z < 0.0) return obj.error(key, "components must be >= 0");
  return *v;
}

Expected<glm::dvec3> unit_direction(const JsonObject& obj, std::string_view key, glm::dvec3 fallback) {
  auto v = obj.vec3(key, fallback);
  if (!v) return v.error();
  const double len = glm::length(*v);
  if (!(len > 1e-9)) return obj.error(key, "must be a non-zero vector");
  return *v / len;
}

Expected<RefMaterial> parse_material(const JsonObject& m) {
  MRGI_TRY(m.only_keys({"type", "color", "roughness", "metallic", "ior", "emission"}));
  RefMaterial out;
  auto type = m.string("type", std::string("diffuse"));
  if (!type) return type.error();
  if (*type == "diffuse") out.type = MaterialType::Diffuse;
  else if (*type == "glossy") out.type = MaterialType::Glossy;
  else if (*type == "mirror") out.type = MaterialType::Mirror;
  else if (*type == "glass") out.type = MaterialType::Glass;
  else return m.error("type", "must be one of diffuse, glossy, mirror, glass");
  auto c = colour(m, "color", glm::dvec3(0.8));
  if (!c) return c.error();
  if (c->x > 1.0 || c->y > 1.0 || c->z > 1.0) return m.error("color", "components must be <= 1 (an albedo)");
  out.base_color = glm::vec3(*c);
  auto rough = m.number("roughness", 0.5);
  if (!rough) return rough.error();
  if (*rough < 0.0 || *rough > 1.0) return m.error("roughness", "must be in [0, 1]");
  out.roughness = float(*rough);
  auto metal = m.number("metallic", 0.0);
  if (!metal) return metal.error();
  if (*metal < 0.0 || *metal > 1.0) return m.error("metallic", "must be in [0, 1]");
  out.metallic = float(*metal);
  auto ior = m.number("ior", 1.5);
  if (!ior) return ior.error();
  if (*ior < 1.0 || *ior > 4.0) return m.error("ior", "must be in [1, 4]");
  out.ior = float(*ior);
  auto e = colour(m, "emission", glm::dvec3(0.0));
  if (!e) return e.error();
  out.emission = glm::vec3(*e);
  return out;
}

Status parse_placement(const JsonObject& o, glm::dvec3* position, glm::dquat* rotation, double* scale) {
  auto p = o.vec3("position", glm::dvec3(0.0));
  if (!p) return p.error();
  auto r = o.quat_xyzw("rotation", glm::dquat(1.0, 0.0, 0.0, 0.0));
  if (!r) return r.error();
  auto s = positive(o, "scale", 1.0);
  if (!s) return s.error();
  *position = *p;
  *rotation = *r;
  *scale = *s;
  return ok_status();
}

Expected<RealObjectDesc> parse_real_object(const JsonObject& o, const fs::path& base) {
  MRGI_TRY(o.only_keys({"shape", "size", "radius", "gltf", "position", "rotation", "scale", "material"}));
  RealObjectDesc d;
  auto shape = o.string("shape");
  if (!shape) return shape.error();
  if (*shape == "plane") d.shape = ShapeKind::Plane;
  else if (*shape == "box") d.shape = ShapeKind::Box;
  else if (*shape == "sphere") d.shape = ShapeKind::Sphere;
  else if (*shape == "gltf") d.shape = ShapeKind::Gltf;
  else return o.error("shape", "must be one of plane, box, sphere, gltf");
  const bool needs_size = d.shape == ShapeKind::Plane || d.shape == ShapeKind::Box;
  if (o.has("size") != needs_size)
    return o.error("size", needs_size ? "is required for this shape" : "is only for plane and box");
  if (needs_size) {
    auto n = fixed_numbers(o, "size", d.shape == ShapeKind::Plane ? 2 : 3);
    if (!n) return n.error();
    for (double v : *n)
      if (!(v > 0.0)) return o.error("size", "edge lengths must be > 0");
    d.size = glm::dvec3((*n)[0], (*n)[1], n->size() > 2 ? (*n)[2] : 0.0);
  }
  if (o.has("radius") != (d.shape == ShapeKind::Sphere))
    return o.error("radius", d.shape == ShapeKind::Sphere ? "is required for a sphere" : "is only for spheres");
  if (d.shape == ShapeKind::Sphere) {
    auto r = positive(o, "radius", 0.5);
    if (!r) return r.error();
    d.radius = *r;
  }
  if (o.has("gltf") != (d.shape == ShapeKind::Gltf))
    return o.error("gltf", d.shape == ShapeKind::Gltf ? "is required for shape gltf" : "is only for shape gltf");
  if (d.shape == ShapeKind::Gltf) {
    auto g = existing_file(o, "gltf", base);
    if (!g) return g.error();
    d.gltf = *g;
  }
  MRGI_TRY(parse_placement(o, &d.position, &d.rotation, &d.scale));
  if (o.has("material")) {
    auto m = o.object("material");
    if (!m) return m.error();
    auto mat = parse_material(*m);
    if (!mat) return mat.error();
    d.material = *mat;
  } else if (d.shape != ShapeKind::Gltf) {
    return o.error("material", "is required for generated shapes");
  }
  return d;
}

Expected<LampDesc> parse_lamp(const JsonObject& o) {
  MRGI_TRY(o.only_keys({"type", "real", "position", "direction", "color", "intensity", "inner_angle_deg",
                        "outer_angle_deg", "size"}));
  LampDesc l;
  auto type = o.string("type");
  if (!type) return type.error();
  if (*type == "point") l.type = LampKind::Point;
  else if (*type == "spot") l.type = LampKind::Spot;
  else if (*type == "directional") l.type = LampKind::Directional;
  else if (*type == "area") l.type = LampKind::Area;
  else return o.error("type", "must be one of point, spot, directional, area");
  auto real = o.boolean("real", true);
  if (!real) return real.error();
  l.real = *real;
  if (l.type != LampKind::Directional) {
    auto p = o.vec3("position");
    if (!p) return p.error();
    l.position = *p;
  } else if (o.has("position")) {
    return o.error("position", "is not used by a directional lamp");
  }
  if (l.type != LampKind::Point) {
    auto d = unit_direction(o, "direction", glm::dvec3(0.0, -1.0, 0.0));
    if (!d) return d.error();
    l.direction = *d;
  } else if (o.has("direction")) {
    return o.error("direction", "is not used by a point lamp");
  }
  auto c = colour(o, "color", glm::dvec3(1.0));
  if (!c) return c.error();
  l.color = *c;
  auto i = non_negative(o, "intensity", 1.0);
  if (!i) return i.error();
  l.intensity = *i;
  const bool spot = l.type == LampKind::Spot;
  if (!spot && (o.has("inner_angle_deg") || o.has("outer_angle_deg")))
    return o.error(o.has("inner_angle_deg") ? "inner_angle_deg" : "outer_angle_deg", "is only for spot lamps");
  if (spot) {
    auto in = o.number("inner_angle_deg", 30.0);
    if (!in) return in.error();
    auto out = o.number("outer_angle_deg", 45.0);
    if (!out) return out.error();
    if (*in < 0.0 || *out > 90.0 || *in > *out)
      return o.error("inner_angle_deg", "must satisfy 0 <= inner_angle_deg <= outer_angle_deg <= 90");
    l.inner_angle_deg = *in;
    l.outer_angle_deg = *out;
  }
  if (o.has("size") != (l.type == LampKind::Area))
    return o.error("size", l.type == LampKind::Area ? "is required for an area lamp" : "is only for area lamps");
  if (l.type == LampKind::Area) {
    auto n = fixed_numbers(o, "size", 2);
    if (!n) return n.error();
    if (!((*n)[0] > 0.0 && (*n)[1] > 0.0)) return o.error("size", "edge lengths must be > 0");
    l.size = glm::dvec2((*n)[0], (*n)[1]);
  }
  return l;
}

Status parse_depth_sensor(const JsonObject& o, DepthSensorSettings* s) {
  MRGI_TRY(o.only_keys({"depth_scale", "min_range_m", "max_range_m", "baseline_m", "focal_px", "disparity_step_px",
                        "axial_noise", "noise_a_m", "noise_b_per_m", "noise_z0_m", "edge_jump_m",
                        "edge_hole_radius_px", "grazing_limit_deg"}));
  struct Field {
    const char* key;
    double* value;
    bool must_be_positive;
  };
  const Field fields[] = {{"depth_scale", &s->depth_scale, true},    {"min_range_m", &s->min_range_m, false},
                          {"max_range_m", &s->max_range_m, true},    {"baseline_m", &s->baseline_m, true},
                          {"focal_px", &s->focal_px, true},          {"disparity_step_px", &s->disparity_step_px, false},
                          {"noise_a_m", &s->noise_a_m, false},       {"noise_b_per_m", &s->noise_b_per_m, false},
                          {"noise_z0_m", &s->noise_z0_m, false},     {"edge_jump_m", &s->edge_jump_m, false},
                          {"grazing_limit_deg", &s->grazing_limit_deg, true}};
  for (const Field& f : fields) {
    auto v = f.must_be_positive ? positive(o, f.key, *f.value) : non_negative(o, f.key, *f.value);
    if (!v) return v.error();
    *f.value = *v;
  }
  auto noise = o.boolean("axial_noise", s->axial_noise);
  if (!noise) return noise.error();
  s->axial_noise = *noise;
  auto r = o.integer("edge_hole_radius_px", s->edge_hole_radius_px);
  if (!r) return r.error();
  if (*r < 0 || *r > 16) return o.error("edge_hole_radius_px", "must be in [0, 16]");
  s->edge_hole_radius_px = *r;
  if (s->max_range_m <= s->min_range_m) return o.error("max_range_m", "must be > min_range_m");
  if (s->grazing_limit_deg > 90.0) return o.error("grazing_limit_deg", "must be <= 90");
  if (s->max_range_m * s->depth_scale > 65535.0)
    return o.error("depth_scale", "max_range_m * depth_scale must fit 16 bits (<= 65535)");
  return ok_status();
}

Status parse_camera(const JsonObject& o, SceneDescription* d) {
  MRGI_TRY(o.only_keys({"width", "height", "fx", "fy", "cx", "cy", "exposure", "noise"}));
  auto w = o.integer("width", 640);
  if (!w) return w.error();
  auto h = o.integer("height", 480);
  if (!h) return h.error();
  if (*w < 1 || *w > 8192) return o.error("width", "must be in [1, 8192]");
  if (*h < 1 || *h > 8192) return o.error("height", "must be in [1, 8192]");
  Intrinsics& k = d->intrinsics;
  k.width = *w;
  k.height = *h;
  auto fx = positive(o, "fx", 525.0);
  if (!fx) return fx.error();
  auto fy = positive(o, "fy", *fx);
  if (!fy) return fy.error();
  auto cx = o.number("cx", 0.5 * (*w - 1));
  if (!cx) return cx.error();
  auto cy = o.number("cy", 0.5 * (*h - 1));
  if (!cy) return cy.error();
  k.fx = *fx, k.fy = *fy, k.cx = *cx, k.cy = *cy;
  auto e = positive(o, "exposure", 1.0);
  if (!e) return e.error();
  d->exposure = *e;
  if (o.has("noise")) {
    auto n = o.object("noise");
    if (!n) return n.error();
    MRGI_TRY(n->only_keys({"full_well_electrons", "read_noise_electrons"}));
    auto fw = non_negative(*n, "full_well_electrons", 0.0);
    if (!fw) return fw.error();
    auto rn = non_negative(*n, "read_noise_electrons", 0.0);
    if (!rn) return rn.error();
    d->noise.full_well_electrons = *fw;
    d->noise.read_noise_electrons = *rn;
  }
  return ok_status();
}

Status parse_render(const JsonObject& o, SceneDescription* d) {
  MRGI_TRY(o.only_keys({"spp", "max_depth", "rr_depth", "seed"}));
  auto spp = o.integer("spp", d->spp);
  if (!spp) return spp.error();
  if (*spp < 1 || *spp > 1 << 20) return o.error("spp", "must be in [1, 1048576]");
  auto md = o.integer("max_depth", d->max_depth);
  if (!md) return md.error();
  if (*md < 0 || *md > 64) return o.error("max_depth", "must be in [0, 64]");
  auto rr = o.integer("rr_depth", d->rr_depth);
  if (!rr) return rr.error();
  if (*rr < 1) return o.error("rr_depth", "must be >= 1");
  auto seed = o.integer("seed", 1);
  if (!seed) return seed.error();
  if (*seed < 0) return o.error("seed", "must be >= 0");
  d->spp = *spp, d->max_depth = *md, d->rr_depth = *rr, d->seed = uint64_t(*seed);
  return ok_status();
}

}  // namespace

Expected<SceneDescription> load_scene_description(const std::string& path) {
  auto json = load_json_file(path);
  if (!json) return json.error();
  auto root = JsonObject::from(*json, path, "");
  if (!root) return root.error();
  MRGI_TRY(root->only_keys({"version", "frames", "fps", "camera", "camera_path", "render", "real_objects", "lights",
                            "environment", "virtual_objects", "depth_sensor", "env_camera", "light_probe"}));
  const fs::path base = fs::path(path).parent_path();
  SceneDescription d;
  d.path = path;
  auto version = root->integer("version");
  if (!version) return version.error();
  if (*version != 1) return root->error("version", "must be 1");
  auto frames = root->integer("frames", 8);
  if (!frames) return frames.error();
  if (*frames < 1 || *frames > 100000) return root->error("frames", "must be in [1, 100000]");
  d.frames = *frames;
  auto fps = positive(*root, "fps", 30.0);
  if (!fps) return fps.error();
  d.fps = *fps;

  auto camera = root->object("camera");
  if (!camera) return camera.error();
  MRGI_TRY(parse_camera(*camera, &d));

  auto keys = root->objects("camera_path");
  if (!keys) return keys.error();
  if (keys->empty()) return root->error("camera_path", "needs at least one keyframe");
  for (const JsonObject& k : *keys) {
    MRGI_TRY(k.only_keys({"time", "position", "look_at", "up"}));
    CameraKeyframe kf;
    auto t = k.number("time", 0.0);
    if (!t) return t.error();
    auto p = k.vec3("position");
    if (!p) return p.error();
    auto la = k.vec3("look_at");
    if (!la) return la.error();
    auto up = unit_direction(k, "up", glm::dvec3(0.0, 1.0, 0.0));
    if (!up) return up.error();
    kf.time = *t, kf.position = *p, kf.look_at = *la, kf.up = *up;
    const glm::dvec3 fwd = kf.look_at - kf.position;
    if (glm::length(fwd) < 1e-9) return k.error("look_at", "must differ from position");
    if (glm::length(glm::cross(glm::normalize(fwd), kf.up)) < 1e-6)
      return k.error("up", "must not be parallel to the viewing direction");
    if (!d.camera_path.empty() && !(kf.time > d.camera_path.back().time))
      return k.error("time", "keyframe times must be strictly increasing");
    d.camera_path.push_back(kf);
  }

  if (root->has("render")) {
    auto r = root->object("render");
    if (!r) return r.error();
    MRGI_TRY(parse_render(*r, &d));
  }
  if (root->has("real_objects")) {
    auto objs = root->objects("real_objects");
    if (!objs) return objs.error();
    for (const JsonObject& o : *objs) {
      auto obj = parse_real_object(o, base);
      if (!obj) return obj.error();
      d.real_objects.push_back(*obj);
    }
  }
  if (root->has("lights")) {
    auto lamps = root->objects("lights");
    if (!lamps) return lamps.error();
    for (const JsonObject& o : *lamps) {
      auto lamp = parse_lamp(o);
      if (!lamp) return lamp.error();
      d.lights.push_back(*lamp);
    }
  }
  if (root->has("environment")) {
    auto e = root->object("environment");
    if (!e) return e.error();
    MRGI_TRY(e->only_keys({"image", "sky", "intensity", "rotation", "capture_width"}));
    if (e->has("image") == e->has("sky")) return e->error("image", "give exactly one of \"image\" and \"sky\"");
    std::string img_path;
    std::optional<ProceduralSky> sky;
    if (e->has("image")) {
      auto img = existing_file(*e, "image", base);
      if (!img) return img.error();
      img_path = *img;
    } else {
      auto so = e->object("sky");
      if (!so) return so.error();
      MRGI_TRY(so->only_keys({"sun_direction", "sun_irradiance", "sun_radius_deg", "zenith", "horizon", "ground", "width"}));
      ProceduralSky k;
      auto dir = unit_direction(*so, "sun_direction", k.sun_direction);
      if (!dir) return dir.error();
      auto irr = colour(*so, "sun_irradiance", k.sun_irradiance);
      if (!irr) return irr.error();
      auto rad = so->number("sun_radius_deg", k.sun_radius_deg);
      if (!rad) return rad.error();
      if (!(*rad >= 0.3 && *rad <= 10.0)) return so->error("sun_radius_deg", "must be in [0.3, 10] degrees");
      auto zen = colour(*so, "zenith", k.zenith);
      if (!zen) return zen.error();
      auto hor = colour(*so, "horizon", k.horizon);
      if (!hor) return hor.error();
      auto gro = colour(*so, "ground", k.ground);
      if (!gro) return gro.error();
      auto w = so->integer("width", k.width);
      if (!w) return w.error();
      if (*w < 64 || *w > 4096 || *w % 2 != 0) return so->error("width", "must be an even number in [64, 4096]");
      k = {*dir, *irr, *rad, *zen, *hor, *gro, int(*w)};
      sky = k;
    }
    auto in = non_negative(*e, "intensity", 1.0);
    if (!in) return in.error();
    auto rot = e->quat_xyzw("rotation", glm::dquat(1.0, 0.0, 0.0, 0.0));
    if (!rot) return rot.error();
    auto cw = e->integer("capture_width", 256);
    if (!cw) return cw.error();
    if (*cw < 0 || *cw > 8192 || *cw % 2 != 0) return e->error("capture_width", "must be an even number in [0, 8192]");
    d.environment = {true, img_path, sky, *in, *rot, *cw};
  }
  if (root->has("virtual_objects")) {
    auto objs = root->objects("virtual_objects");
    if (!objs) return objs.error();
    for (const JsonObject& o : *objs) {
      MRGI_TRY(o.only_keys({"gltf", "position", "rotation", "scale", "velocity", "angular_velocity_deg"}));
      VirtualObjectMotionDesc v;
      auto g = existing_file(o, "gltf", base);
      if (!g) return g.error();
      v.gltf = *g;
      MRGI_TRY(parse_placement(o, &v.position, &v.rotation, &v.scale));
      auto vel = o.vec3("velocity", glm::dvec3(0.0));
      if (!vel) return vel.error();
      auto av = o.vec3("angular_velocity_deg", glm::dvec3(0.0));
      if (!av) return av.error();
      v.velocity = *vel, v.angular_velocity_deg = *av;
      d.virtual_objects.push_back(v);
    }
  }
  if (root->has("depth_sensor")) {
    auto ds = root->object("depth_sensor");
    if (!ds) return ds.error();
    MRGI_TRY(parse_depth_sensor(*ds, &d.depth));
  }
  if (root->has("env_camera")) {
    auto e = root->object("env_camera");
    if (!e) return e.error();
    MRGI_TRY(e->only_keys({"position", "look_at", "up", "size", "fov_deg", "spp"}));
    EnvCameraDesc c;
    auto p = e->vec3("position");
    if (!p) return p.error();
    auto la = e->vec3("look_at");
    if (!la) return la.error();
    auto up = unit_direction(*e, "up", glm::dvec3(0.0, 0.0, 1.0));
    if (!up) return up.error();
    auto size = e->integer("size", 256);
    if (!size) return size.error();
    if (*size < 8 || *size > 4096) return e->error("size", "must be in [8, 4096]");
    auto fov = e->number("fov_deg", 180.0);
    if (!fov) return fov.error();
    if (!(*fov > 0.0 && *fov <= 360.0)) return e->error("fov_deg", "must be in (0, 360]");
    auto spp = e->integer("spp", 16);
    if (!spp) return spp.error();
    if (*spp < 1) return e->error("spp", "must be >= 1");
    c.position = *p, c.look_at = *la, c.up = *up, c.size = *size, c.fov_deg = *fov, c.spp = *spp;
    if (glm::length(glm::cross(glm::normalize(c.look_at - c.position), c.up)) < 1e-6)
      return e->error("up", "must not be parallel to the viewing direction (and look_at must differ from position)");
    d.env_camera = c;
  }
  if (root->has("light_probe")) {
    auto lp = root->object("light_probe");
    if (!lp) return lp.error();
    MRGI_TRY(lp->only_keys({"width", "spp"}));
    auto w = lp->integer("width", 64);
    if (!w) return w.error();
    if (*w < 8 || *w > 1024 || *w % 2 != 0) return lp->error("width", "must be an even number in [8, 1024]");
    auto spp = lp->integer("spp", 256);
    if (!spp) return spp.error();
    if (*spp < 1 || *spp > (1 << 20)) return lp->error("spp", "must be in [1, 1048576]");
    if (d.virtual_objects.empty()) return lp->error("width", "a light probe needs a virtual object (it sits at their centre)");
    d.light_probe = LightProbeDesc{int(*w), int(*spp)};
  }
  if (d.environment.present && d.environment.capture_width == 0 && !d.env_camera)
    return root->error("environment", "capture_width 0 needs an env_camera, else the capture has no environment");
  return d;
}

glm::dquat look_rotation(const glm::dvec3& position, const glm::dvec3& look_at, const glm::dvec3& up) {
  const glm::dvec3 z = glm::normalize(look_at - position);
  const glm::dvec3 x = glm::normalize(glm::cross(z, up));
  const glm::dvec3 y = glm::cross(z, x);  // OpenCV: y points down in the image
  return glm::normalize(glm::quat_cast(glm::dmat3(x, y, z)));
}

Pose camera_pose_at(const SceneDescription& d, double t) {
  const auto& keys = d.camera_path;
  CameraKeyframe k = keys.front();
  if (t >= keys.back().time) {
    k = keys.back();
  } else if (t > keys.front().time) {
    size_t i = 1;
    while (keys[i].time < t) ++i;
    const CameraKeyframe &a = keys[i - 1], &b = keys[i];
    const double s = (t - a.time) / (b.time - a.time);
    k.position = glm::mix(a.position, b.position, s);
    k.look_at = glm::mix(a.look_at, b.look_at, s);
    k.up = glm::normalize(glm::mix(a.up, b.up, s));
    // Interpolation can pass through a degenerate frame (look-at on the camera, up along the view
    // or opposite ups); hold the earlier keyframe's orientation there instead of producing NaN.
    const glm::dvec3 fwd = k.look_at - k.position;
    if (!(glm::length(fwd) > 1e-9) || !(glm::length(glm::cross(glm::normalize(fwd), k.up)) > 1e-6) ||
        !std::isfinite(k.up.x)) {
      k.look_at = k.position + (a.look_at - a.position);
      k.up = a.up;
    }
  }
  Pose pose;
  pose.translation = k.position;
  pose.rotation = look_rotation(k.position, k.look_at, k.up);
  return pose;
}

}  // namespace mrgi::reference

namespace mrgi::reference {

ImageRGBF render_sky(const ProceduralSky& sky) {
  constexpr double kPi = 3.14159265358979323846;
  const int w = sky.width, h = sky.width / 2;
  ImageRGBF img(w, h);
  const glm::dvec3 sun = glm::normalize(sky.sun_direction);
  const double cos_r = std::cos(sky.sun_radius_deg * kPi / 180.0);
  auto direction = [&](int u, int v) {
    const double theta = (v + 0.5) / h * kPi, phi = ((u + 0.5) / w - 0.5) * 2.0 * kPi;
    return glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  };
  // The disc's pixels cover another solid angle than the analytic disc: their radiance is set so
  // they carry the sun's irradiance exactly (a disc smaller than a pixel still gets its pixel).
  double covered = 0.0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      if (glm::dot(direction(u, v), sun) >= cos_r)
        covered += std::sin((v + 0.5) / h * kPi) * (kPi / h) * (2.0 * kPi / w);
  int nearest_u = 0, nearest_v = 0;
  double nearest = -2.0;
  if (covered == 0.0) {  // no pixel centre inside: the nearest pixel carries the sun
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u)
        if (const double c = glm::dot(direction(u, v), sun); c > nearest) {
          nearest = c;
          nearest_u = u;
          nearest_v = v;
        }
    covered = std::sin((nearest_v + 0.5) / h * kPi) * (kPi / h) * (2.0 * kPi / w);
  }
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const glm::dvec3 d = direction(u, v);
      glm::dvec3 l = d.y > 0.0 ? sky.horizon + (sky.zenith - sky.horizon) * std::sqrt(d.y) : sky.ground;
      const bool in_disc = nearest > -2.0 ? (u == nearest_u && v == nearest_v) : glm::dot(d, sun) >= cos_r;
      if (in_disc) l += sky.sun_irradiance / covered;
      float* t = img.at(u, v);
      t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z);
    }
  return img;
}

}  // namespace mrgi::reference
