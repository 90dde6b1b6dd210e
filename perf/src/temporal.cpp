#include "mrgi/perf/temporal.h"

#include <cmath>
#include <string>

#include "mrgi/metrics.h"

namespace mrgi::perf {
namespace {

// The same surface: depths within this fraction of each other.
constexpr double kSameSurface = 0.02;

template <class I>
Status check_size(const I* img, const char* what, const Intrinsics& k, bool required) {
  if (!img) return required ? fail(ErrorKind::BadInput, std::string("delta_stability: no ") + what) : ok_status();
  if (img->width != k.width || img->height != k.height)
    return fail(ErrorKind::BadInput, std::string("delta_stability: ") + what + " is " + std::to_string(img->width) +
                                         "x" + std::to_string(img->height) + ", the camera " +
                                         std::to_string(k.width) + "x" + std::to_string(k.height));
  return ok_status();
}

Status check_frame(const StabilityFrame& f, const Intrinsics& k) {
  MRGI_TRY(check_size(f.camera, "camera", k, true));
  MRGI_TRY(check_size(f.output, "output", k, true));
  MRGI_TRY(check_size(f.depth, "depth", k, true));
  MRGI_TRY(check_size(f.reference, "reference", k, false));
  MRGI_TRY(check_size(f.virtual_mask, "virtual mask", k, false));
  return ok_status();
}

bool is_real(const StabilityFrame& f, size_t i) { return !f.virtual_mask || f.virtual_mask->data[i] == 0; }

}  // namespace

Expected<StabilityPair> delta_stability(const StabilityFrame& previous, const StabilityFrame& current,
                                        const Intrinsics& k, double depth_scale) {
  MRGI_TRY(check_frame(previous, k));
  MRGI_TRY(check_frame(current, k));
  if (!(depth_scale > 0.0)) return fail(ErrorKind::BadInput, "delta_stability: depth_scale must be > 0");
  const glm::dmat4 to_previous = glm::inverse(previous.camera_to_world) * current.camera_to_world;
  const bool truth = previous.reference && current.reference;
  StabilityPair out;
  out.has_truth = truth;
  double sum_out = 0.0, sum_truth = 0.0;
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const size_t i = size_t(v) * size_t(k.width) + size_t(u);
      const double z = current.depth->data[i] / depth_scale;
      if (!(z > 0.0) || !is_real(current, i)) continue;
      const glm::dvec4 p((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z, 1.0);
      const glm::dvec4 q = to_previous * p;
      if (!(q.z > 0.0)) continue;
      const long up = std::lround(q.x / q.z * k.fx + k.cx), vp = std::lround(q.y / q.z * k.fy + k.cy);
      if (up < 0 || vp < 0 || up >= k.width || vp >= k.height) continue;
      const size_t j = size_t(vp) * size_t(k.width) + size_t(up);
      const double z0 = previous.depth->data[j] / depth_scale;
      if (!(z0 > 0.0) || std::abs(z0 - q.z) > kSameSurface * q.z || !is_real(previous, j)) continue;
      ++out.pixels;
      for (int c = 0; c < 3; ++c) {
        const double c1 = srgb8_to_linear(current.camera->data[i * 3 + c]);
        const double c0 = srgb8_to_linear(previous.camera->data[j * 3 + c]);
        const double d1 = srgb8_to_linear(current.output->data[i * 4 + c]) - c1;
        const double d0 = srgb8_to_linear(previous.output->data[j * 4 + c]) - c0;
        sum_out += std::abs(d1 - d0);
        if (truth) {
          const double g1 = srgb8_to_linear(current.reference->data[i * 3 + c]) - c1;
          const double g0 = srgb8_to_linear(previous.reference->data[j * 3 + c]) - c0;
          sum_truth += std::abs(g1 - g0);
        }
      }
    }
  if (out.pixels > 0) {
    out.output_change = sum_out / (3.0 * double(out.pixels));
    out.truth_change = truth ? sum_truth / (3.0 * double(out.pixels)) : 0.0;
  }
  return out;
}

}  // namespace mrgi::perf
