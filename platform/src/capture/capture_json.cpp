// capture.json v1. Keys:
//   version      required, 1
//   color        {width, height, fx, fy, cx, cy} (all six; width/height > 0, fx/fy > 0)
//                default: TUM Freiburg 1, 640x480, fx 517.3 fy 516.5 cx 318.6 cy 255.3
//   depth        same shape; default: equal to `color` (depth registered to colour)
//   depth_scale  > 0 depth units per metre, default 5000 (TUM)
//   exposure     > 0, default 1
//   env_camera   {model "equirectangular" | "fisheye_equidistant", f (px, fisheye: required > 0),
//                 cx, cy (px, fisheye: required), fov_deg (fisheye, (0, 360], default 180),
//                 rotation [x,y,z,w] (default identity), position [x,y,z] (world metres,
//                 optional: where the env camera is, so declared lamps it sees can be removed)}
//   apriltag     {family (an AprilTag library family name, default tag36h11), size_m > 0 (default
//                 0.1), tags [{id >= 0 (unique), position [3], rotation [x,y,z,w]}]}
// Unknown keys, wrong types and out-of-range values are refused naming file, key path and rule.
#include <set>

#include "capture/capture_text.h"
#include "mrgi/json_reader.h"
#include "mrgi/platform/capture.h"

namespace mrgi {
namespace {

constexpr int kCaptureVersion = 1;

Expected<Intrinsics> read_intrinsics(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"width", "height", "fx", "fy", "cx", "cy"}));
  Intrinsics k;
  auto w = obj.integer("width");
  if (!w) return w.error();
  auto h = obj.integer("height");
  if (!h) return h.error();
  if (*w <= 0 || *w > 16384) return obj.error("width", "must be in [1, 16384] pixels");
  if (*h <= 0 || *h > 16384) return obj.error("height", "must be in [1, 16384] pixels");
  k.width = *w;
  k.height = *h;
  for (auto [key, out] : {std::pair{"fx", &k.fx}, {"fy", &k.fy}, {"cx", &k.cx}, {"cy", &k.cy}}) {
    auto v = obj.number(key);
    if (!v) return v.error();
    *out = *v;
  }
  if (k.fx <= 0) return obj.error("fx", "focal length must be > 0 pixels");
  if (k.fy <= 0) return obj.error("fy", "focal length must be > 0 pixels");
  return k;
}

Expected<EnvCamera> read_env_camera(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"model", "f", "cx", "cy", "fov_deg", "rotation", "position"}));
  EnvCamera cam;
  auto model = obj.string("model");
  if (!model) return model.error();
  if (*model == "equirectangular") {
    cam.model = EnvModel::Equirectangular;
    for (std::string_view key : {"f", "cx", "cy", "fov_deg"})
      if (obj.has(key)) return obj.error(key, "applies to model \"fisheye_equidistant\" only");
  } else if (*model == "fisheye_equidistant") {
    cam.model = EnvModel::FisheyeEquidistant;
    auto f = obj.number("f");
    if (!f) return f.error();
    if (*f <= 0) return obj.error("f", "must be > 0 pixels per radian");
    auto cx = obj.number("cx");
    if (!cx) return cx.error();
    auto cy = obj.number("cy");
    if (!cy) return cy.error();
    auto fov = obj.number("fov_deg", 180.0);
    if (!fov) return fov.error();
    if (!(*fov > 0 && *fov <= 360)) return obj.error("fov_deg", "must be in (0, 360] degrees");
    cam.f = *f;
    cam.cx = *cx;
    cam.cy = *cy;
    cam.fov_deg = *fov;
  } else {
    return obj.error("model", "must be \"equirectangular\" or \"fisheye_equidistant\", got \"" + *model + "\"");
  }
  auto rot = obj.quat_xyzw("rotation", glm::dquat(1.0, 0.0, 0.0, 0.0));
  if (!rot) return rot.error();
  cam.rotation = *rot;
  if (obj.has("position")) {
    auto pos = obj.vec3("position");
    if (!pos) return pos.error();
    cam.position = *pos;
  }
  return cam;
}

Expected<AprilTagSettings> read_apriltag(const JsonObject& obj) {
  MRGI_TRY(obj.only_keys({"family", "size_m", "tags"}));
  AprilTagSettings tags;
  auto family = obj.string("family", tags.family);
  if (!family) return family.error();
  static const std::set<std::string> kFamilies = {"tag36h11", "tag25h9", "tag16h5", "tagCircle21h7",
                                                  "tagCircle49h12", "tagStandard41h12",
                                                  "tagStandard52h13", "tagCustom48h12"};
  if (!kFamilies.count(*family))
    return obj.error("family", "unknown AprilTag family \"" + *family +
                                   "\" (expected one of the AprilTag library's, e.g. tag36h11)");
  tags.family = *family;
  auto size = obj.number("size_m", tags.size_m);
  if (!size) return size.error();
  if (*size <= 0) return obj.error("size_m", "must be > 0 metres");
  tags.size_m = *size;
  if (obj.has("tags")) {
    auto list = obj.objects("tags");
    if (!list) return list.error();
    std::set<int> seen;
    for (const JsonObject& t : *list) {
      MRGI_TRY(t.only_keys({"id", "position", "rotation"}));
      auto id = t.integer("id");
      if (!id) return id.error();
      if (*id < 0) return t.error("id", "must be >= 0");
      if (!seen.insert(*id).second) return t.error("id", "tag id " + std::to_string(*id) + " is listed twice");
      auto pos = t.vec3("position");
      if (!pos) return pos.error();
      auto rot = t.quat_xyzw("rotation");
      if (!rot) return rot.error();
      TagPose pose;
      pose.id = *id;
      pose.tag_to_world.translation = *pos;
      pose.tag_to_world.rotation = *rot;
      tags.tags.push_back(pose);
    }
  }
  return tags;
}

nlohmann::json intrinsics_json(const Intrinsics& k) {
  return {{"width", k.width}, {"height", k.height}, {"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}};
}

}  // namespace

Expected<CaptureInfo> load_capture_json(const std::string& path) {
  auto json = load_json_file(path);
  if (!json) return json.error();
  auto root = JsonObject::from(*json, path, "");
  if (!root) return root.error();
  MRGI_TRY(root->only_keys({"version", "color", "depth", "depth_scale", "exposure", "env_camera", "apriltag"}));
  CaptureInfo info;
  auto version = root->integer("version");
  if (!version) return version.error();
  if (*version != kCaptureVersion)
    return root->error("version", "unsupported capture.json version " + std::to_string(*version) +
                                      " (this build reads version 1)");
  if (root->has("color")) {
    auto obj = root->object("color");
    if (!obj) return obj.error();
    auto k = read_intrinsics(*obj);
    if (!k) return k.error();
    info.color = *k;
  }
  info.depth = info.color;
  if (root->has("depth")) {
    auto obj = root->object("depth");
    if (!obj) return obj.error();
    auto k = read_intrinsics(*obj);
    if (!k) return k.error();
    info.depth = *k;
  }
  auto scale = root->number("depth_scale", info.depth_scale);
  if (!scale) return scale.error();
  if (*scale <= 0) return root->error("depth_scale", "must be > 0 depth units per metre");
  info.depth_scale = *scale;
  auto exposure = root->number("exposure", info.exposure);
  if (!exposure) return exposure.error();
  if (*exposure <= 0) return root->error("exposure", "must be > 0");
  info.exposure = *exposure;
  if (root->has("env_camera")) {
    auto obj = root->object("env_camera");
    if (!obj) return obj.error();
    auto cam = read_env_camera(*obj);
    if (!cam) return cam.error();
    info.env_camera = *cam;
  }
  if (root->has("apriltag")) {
    auto obj = root->object("apriltag");
    if (!obj) return obj.error();
    auto tags = read_apriltag(*obj);
    if (!tags) return tags.error();
    info.apriltag = *tags;
  }
  return info;
}

Status write_capture_json(const std::string& path, const CaptureInfo& info) {
  nlohmann::json j;
  j["version"] = kCaptureVersion;
  j["color"] = intrinsics_json(info.color);
  j["depth"] = intrinsics_json(info.depth);
  j["depth_scale"] = info.depth_scale;
  j["exposure"] = info.exposure;
  if (info.env_camera) {
    const EnvCamera& cam = *info.env_camera;
    nlohmann::json e;
    if (cam.model == EnvModel::Equirectangular) {
      e["model"] = "equirectangular";
    } else {
      e["model"] = "fisheye_equidistant";
      e["f"] = cam.f;
      e["cx"] = cam.cx;
      e["cy"] = cam.cy;
      e["fov_deg"] = cam.fov_deg;
    }
    e["rotation"] = to_json_xyzw(cam.rotation);
    if (cam.position) e["position"] = {cam.position->x, cam.position->y, cam.position->z};
    j["env_camera"] = e;
  }
  if (info.apriltag) {
    nlohmann::json a;
    a["family"] = info.apriltag->family;
    a["size_m"] = info.apriltag->size_m;
    a["tags"] = nlohmann::json::array();
    for (const TagPose& t : info.apriltag->tags)
      a["tags"].push_back({{"id", t.id},
                           {"position", to_json_array(t.tag_to_world.translation)},
                           {"rotation", to_json_xyzw(t.tag_to_world.rotation)}});
    j["apriltag"] = a;
  }
  return capture::write_text(path, j.dump(2) + "\n");
}

}  // namespace mrgi
