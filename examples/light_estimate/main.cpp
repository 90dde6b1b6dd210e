// The light estimate: with no lamp and no environment declared, the runtime estimates the real
// light from colour and depth (the probeless estimate) and hands it back with every frame
// (FrameOutput::light): SH radiance, the dominant light's direction and intensity, a confidence.
// An app lights its own content with it. The frames here are made up: a room corner (a floor and
// two walls, grey) lit by a sun from a known direction plus a dim sky, seen by a camera in the
// room; the example prints the estimated direction beside the true one. The light stage runs
// on frames where something virtual is lit with its answer, so a virtual object (any glTF)
// stands on the floor.
//
//   light_estimate OBJECT.gltf
//
// Exit 0 when the estimate is valid and within 45 degrees of the sun (a three-surface view pins
// the direction only roughly; perf/results/light-family/ has the measured accuracy).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <mrgi/runtime.h>
#include <mrgi/version.h>

namespace {

const glm::dvec3 kSun = glm::normalize(glm::dvec3(0.4, 0.8, -0.45));  // towards the sun

// Nearest of the floor (y = 0), the back wall (z = 1.5) and the left wall (x = -1.2) along a ray.
bool hit(const glm::dvec3& o, const glm::dvec3& d, double& t, glm::dvec3& n) {
  t = 1e30;
  auto plane = [&](double along, double at, int axis, const glm::dvec3& normal) {
    if (std::abs(along) < 1e-9) return;
    const double s = (at - o[axis]) / along;
    if (s > 1e-6 && s < t) {
      t = s;
      n = normal;
    }
  };
  plane(d.y, 0.0, 1, {0, 1, 0});
  plane(d.z, 1.5, 2, {0, 0, -1});
  plane(d.x, -1.2, 0, {1, 0, 0});
  return t < 1e29;
}

mrgi::InputFrame make_frame(int64_t index, const mrgi::Intrinsics& k, double depth_scale, const mrgi::Pose& pose) {
  mrgi::InputFrame f;
  f.index = index;
  f.timestamp = f.depth_timestamp = double(index) / 30.0;
  f.color = mrgi::ImageRGB8(k.width, k.height);
  f.depth = mrgi::ImageU16(k.width, k.height);
  f.pose = pose;
  const glm::dmat4 m = pose.matrix();
  const glm::dvec3 eye(m[3]);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      const glm::dvec3 dc((x - k.cx) / k.fx, (y - k.cy) / k.fy, 1.0);
      const glm::dvec3 d = glm::normalize(glm::dvec3(m * glm::dvec4(dc, 0.0)));
      double t;
      glm::dvec3 n;
      if (!hit(eye, d, t, n)) continue;
      const glm::dvec3 p = eye + t * d;
      // Lambert, albedo 0.5: the sun (2 W/m^2) where not shadowed by the other surfaces, a sky
      // of 0.05 W/m^2 sr over the hemisphere (irradiance pi x 0.05 on every surface here).
      double ts;
      glm::dvec3 ns;
      const bool lit = glm::dot(n, kSun) > 0.0 && !hit(p + n * 1e-4, kSun, ts, ns);
      const double e = (lit ? 2.0 * glm::dot(n, kSun) : 0.0) + 3.14159265 * 0.05;
      const double radiance = 0.5 / 3.14159265 * e;
      const double srgb = radiance <= 0.0031308 ? 12.92 * radiance : 1.055 * std::pow(radiance, 1.0 / 2.4) - 0.055;
      const uint8_t v = uint8_t(std::clamp(srgb, 0.0, 1.0) * 255.0 + 0.5);
      for (int c = 0; c < 3; ++c) f.color.at(x, y)[c] = v;
      f.depth.at(x, y)[0] = uint16_t(std::lround(glm::dot(p - eye, glm::dvec3(m[2])) * depth_scale));
    }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s OBJECT.gltf\n", argv[0]);
    return 2;
  }
  std::printf("mrgi %s\n", mrgi::version());
  mrgi::CameraSetup cameras;
  cameras.color = cameras.depth = mrgi::Intrinsics{160, 120, 130.0, 130.0, 79.5, 59.5};
  mrgi::RuntimeSettings settings;  // baseline at its cheapest level: the estimate is the stage's
  settings.level = int(mrgi::technique_levels(settings.technique)->size()) - 1;
  mrgi::SceneDesc scene;
  mrgi::VirtualObjectDesc object;
  object.gltf = argv[1];
  object.placement.position = {-0.3f, 0.0f, 0.6f};
  object.placement.scale = glm::vec3(1.5f);
  object.placement.rotation = glm::quat(0.70710678f, 0.70710678f, 0.0f, 0.0f);  // w, x, y, z
  scene.virtual_objects.push_back(object);
  auto runtime = mrgi::create_runtime(settings, cameras, scene);
  if (!runtime) {
    std::fprintf(stderr, "error: %s\n", runtime.error().message.c_str());
    return 1;
  }
  // The camera at (0.9, 1.1, -1.2) looking at (-0.4, 0.3, 0.9): OpenCV axes (x right, y down, z
  // forward) as columns of the camera-to-world rotation.
  const glm::dvec3 eye(0.9, 1.1, -1.2), forward = glm::normalize(glm::dvec3(-0.4, 0.3, 0.9) - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 down = glm::cross(forward, right);
  mrgi::Pose pose;
  pose.translation = eye;
  pose.rotation = glm::quat_cast(glm::dmat3(right, down, forward));

  std::optional<mrgi::LightEstimate> last;
  for (int64_t i = 0; i < 3; ++i) {
    auto outs = (*runtime)->process(make_frame(i, cameras.color, cameras.depth_scale, pose));
    if (!outs) {
      std::fprintf(stderr, "error: %s\n", outs.error().message.c_str());
      return 1;
    }
    for (auto& out : *outs) {
      if (out.light) last = out.light;
      for (const std::string& note : out.stats.notes) std::printf("frame %lld: %s\n", static_cast<long long>(out.stats.frame_index), note.c_str());
    }
  }
  auto rest = (*runtime)->flush();
  if (!rest) {
    std::fprintf(stderr, "error: %s\n", rest.error().message.c_str());
    return 1;
  }
  for (auto& out : *rest)
    if (out.light) last = out.light;
  if (!last || !last->valid) {
    std::printf("no light estimate\n");
    return 1;
  }
  const glm::dvec3 dir(last->direction_to_light[0], last->direction_to_light[1], last->direction_to_light[2]);
  const double err = std::acos(std::clamp(glm::dot(glm::normalize(dir), kSun), -1.0, 1.0)) * 180.0 / 3.14159265;
  std::printf("estimate from frame %lld, confidence %.2f\n", static_cast<long long>(last->frame_index),
              double(last->confidence));
  std::printf("towards the light: (%.2f, %.2f, %.2f), truth (%.2f, %.2f, %.2f): %.1f degrees apart\n", dir.x, dir.y,
              dir.z, kSun.x, kSun.y, kSun.z, err);
  std::printf("dominant light: %.3f %.3f %.3f W/m^2; mean radiance (SH band 0 / 3.545): %.3f\n",
              last->dominant_intensity[0], last->dominant_intensity[1], last->dominant_intensity[2],
              last->sh_radiance[0][0] / 3.5449077);
  return err <= 45.0 ? 0 : 1;
}
