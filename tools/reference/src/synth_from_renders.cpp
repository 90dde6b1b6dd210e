#include "synth_from_renders.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace mrgi::reference {

namespace fs = std::filesystem;

namespace {

std::string frame_file(const std::string& dir, int frame, const char* what) {
  char name[64];
  std::snprintf(name, sizeof name, "%06d_%s.exr", frame, what);
  return (fs::path(dir) / name).string();
}

Error missing(const std::string& path, const char* what) {
  return fail(ErrorKind::BadInput, path + ": missing (the renders must hold NNNNNN_" + what +
                                       ".exr for every frame 0 .. frames - 1 of the description)");
}

// An image of DIR that must exist at WIDTH x HEIGHT; load_hdr_image refuses NaN and Inf by pixel.
Expected<ImageRGBF> load_sized(const std::string& dir, int frame, const char* what, int width, int height) {
  const std::string path = frame_file(dir, frame, what);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return missing(path, what);
  auto img = load_hdr_image(path);
  if (!img) return img.error();
  if (img->width != width || img->height != height)
    return fail(ErrorKind::BadInput, path + ": is " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                                         ", must be " + std::to_string(width) + "x" + std::to_string(height) +
                                         " (the description's camera size)");
  return img;
}

}  // namespace

Status check_renders_present(const std::string& dir, const SceneDescription& d) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(ErrorKind::BadInput, dir + ": is not a folder of renders");
  for (int f = 0; f < d.frames; ++f)
    for (const char* what : {"C", "G", "depth", "normal", "mask", "env"}) {
      if (std::string(what) == "env" && !d.env_camera) continue;
      const std::string path = frame_file(dir, f, what);
      if (!fs::is_regular_file(path, ec)) return missing(path, what);
    }
  return ok_status();
}

Expected<RenderedFrame> load_rendered_frame(const std::string& dir, int frame, const SceneDescription& d,
                                            const Pose& pose) {
  const Intrinsics& k = d.intrinsics;
  RenderedFrame out;
  auto c = load_sized(dir, frame, "C", k.width, k.height);
  if (!c) return c.error();
  auto g = load_sized(dir, frame, "G", k.width, k.height);
  if (!g) return g.error();
  auto depth = load_sized(dir, frame, "depth", k.width, k.height);
  if (!depth) return depth.error();
  auto normal = load_sized(dir, frame, "normal", k.width, k.height);
  if (!normal) return normal.error();
  auto mask = load_sized(dir, frame, "mask", k.width, k.height);
  if (!mask) return mask.error();
  out.render.real = std::move(*c);
  out.render.combined = std::move(*g);

  // The depth sensor's grazing-angle rule needs |cos| between the pixel-centre ray and the
  // surface: the ray through pixel (x, y) (OpenCV, integer coordinates are pixel centres) in world
  // axes against the rendered normal.
  const glm::dmat3 rot = glm::mat3_cast(pose.rotation);
  const size_t n = size_t(k.width) * k.height;
  out.render.depth_z.assign(n, 0.0f);
  out.render.cos_incidence.assign(n, 0.0f);
  out.render.virtual_mask = ImageU8(k.width, k.height);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      const size_t i = size_t(y) * k.width + x;
      out.render.virtual_mask.data[i] = mask->at(x, y)[0] >= 0.5f ? 255 : 0;
      const float z = depth->at(x, y)[0];
      if (!(z > 0.0f)) continue;
      const float* e = normal->at(x, y);
      const glm::dvec3 nw(2.0 * e[0] - 1.0, 2.0 * e[1] - 1.0, 2.0 * e[2] - 1.0);
      const double len = glm::length(nw);
      if (!(len > 0.5))
        return fail(ErrorKind::BadInput, frame_file(dir, frame, "normal") + ": pixel (" + std::to_string(x) + ", " +
                                             std::to_string(y) + ") has depth but no unit normal (0.5 + 0.5 n, |n| = " +
                                             std::to_string(len) + ")");
      const glm::dvec3 ray = rot * glm::normalize(glm::dvec3((x - k.cx) / k.fx, (y - k.cy) / k.fy, 1.0));
      out.render.depth_z[i] = z;
      out.render.cos_incidence[i] = float(std::abs(glm::dot(ray, nw / len)));
    }
  if (d.env_camera) {
    auto env = load_sized(dir, frame, "env", d.env_camera->size, d.env_camera->size);
    if (!env) return env.error();
    out.env = std::move(*env);
  }
  return out;
}

}  // namespace mrgi::reference
