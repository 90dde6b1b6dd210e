#include "mrgi/reference/sensors.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sampling.h"

namespace mrgi::reference {

namespace {

// Standard normal from two hashed uniforms (Box-Muller), keyed so that C and G share it.
float gaussian(uint64_t key, uint32_t dim) {
  const SampleRng rng{key};
  const float u1 = std::max(rng.uniform(2 * dim), 1e-7f);
  const float u2 = rng.uniform(2 * dim + 1);
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
}

constexpr uint64_t kCameraNoiseDomain = 0x43414D4552414E53ull;
constexpr uint64_t kDepthNoiseDomain = 0x44455054484E5345ull;

}  // namespace

Expected<ImageRGB8> camera_frame(const ImageRGBF& radiance, double exposure, const CameraNoiseSettings& noise,
                                 uint64_t seed, uint64_t frame) {
  if (!(exposure > 0.0) || !std::isfinite(exposure))
    return fail(ErrorKind::BadUsage, "camera model: exposure must be finite and > 0");
  if (noise.full_well_electrons < 0.0 || noise.read_noise_electrons < 0.0 ||
      !std::isfinite(noise.full_well_electrons) || !std::isfinite(noise.read_noise_electrons))
    return fail(ErrorKind::BadUsage, "camera model: full_well_electrons and read_noise_electrons must be >= 0");
  ImageRGB8 out(radiance.width, radiance.height);
  const bool noisy = noise.full_well_electrons > 0.0;
  const float inv_fw = noisy ? float(1.0 / noise.full_well_electrons) : 0.0f;
  const float read_sigma = float(noise.read_noise_electrons) * inv_fw;
  const uint64_t frame_key = hash_key(hash_key(kCameraNoiseDomain, seed), frame);
  for (size_t i = 0; i < radiance.pixel_count(); ++i) {
    glm::vec3 x(radiance.data[3 * i], radiance.data[3 * i + 1], radiance.data[3 * i + 2]);
    if (!finite3(x)) x = glm::vec3(0.0f);
    x *= float(exposure);
    if (noisy) {
      const uint64_t key = hash_key(frame_key, i);
      for (int c = 0; c < 3; ++c) {
        const float shot = std::sqrt(std::max(x[c], 0.0f) * inv_fw);
        x[c] += shot * gaussian(key, uint32_t(2 * c)) + read_sigma * gaussian(key, uint32_t(2 * c + 1));
      }
    }
    const glm::vec3 e = camera_response(x, 1.0f);
    for (int c = 0; c < 3; ++c) out.data[3 * i + c] = uint8_t(std::lround(glm::clamp(e[c], 0.0f, 1.0f) * 255.0f));
  }
  return out;
}

double kinect_axial_sigma(const DepthSensorSettings& s, double z) {
  return s.noise_a_m + s.noise_b_per_m * (z - s.noise_z0_m) * (z - s.noise_z0_m);
}

double kinect_quantise(const DepthSensorSettings& s, double z) {
  if (s.disparity_step_px <= 0.0 || z <= 0.0) return z;
  const double fb = s.focal_px * s.baseline_m;
  const double d = std::round(fb / z / s.disparity_step_px) * s.disparity_step_px;
  return d > 0.0 ? fb / d : 0.0;
}

Expected<ImageU16> depth_frame(const std::vector<float>& depth_z, const std::vector<float>& cos_incidence,
                               int width, int height, const DepthSensorSettings& s, uint64_t seed, uint64_t frame) {
  const size_t n = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  if (width <= 0 || height <= 0 || depth_z.size() != n || cos_incidence.size() != n)
    return fail(ErrorKind::BadUsage, "depth model: depth and incidence buffers must hold width*height values");
  if (!(s.depth_scale > 0.0) || !(s.min_range_m >= 0.0) || !(s.max_range_m > s.min_range_m) ||
      !(s.baseline_m > 0.0) || !(s.focal_px > 0.0) || s.disparity_step_px < 0.0 || s.edge_hole_radius_px < 0 ||
      !(s.grazing_limit_deg > 0.0 && s.grazing_limit_deg <= 90.0) || s.noise_a_m < 0.0 || s.noise_b_per_m < 0.0)
    return fail(ErrorKind::BadUsage, "depth model: settings out of range (depth_scale > 0, 0 <= min_range_m < "
                                     "max_range_m, baseline_m > 0, focal_px > 0, grazing_limit_deg in (0, 90])");
  if (s.max_range_m * s.depth_scale > 65535.0)
    return fail(ErrorKind::BadUsage, "depth model: max_range_m * depth_scale = " +
                                         std::to_string(s.max_range_m * s.depth_scale) + " does not fit 16 bits");
  std::vector<uint8_t> hole(n, 0);
  const float cos_limit = float(std::cos(s.grazing_limit_deg * 3.14159265358979323846 / 180.0));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      const float z = depth_z[i];
      if (!(z > 0.0f) || !std::isfinite(z) || cos_incidence[i] < cos_limit) {
        hole[i] = 1;
        continue;
      }
      if (s.edge_jump_m <= 0.0) continue;
      const int nx[4] = {x - 1, x + 1, x, x};
      const int ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= width || ny[k] >= height) continue;
        const float zn = depth_z[size_t(ny[k]) * width + nx[k]];
        if (!(zn > 0.0f) || std::abs(zn - z) > s.edge_jump_m) hole[i] = 2;
      }
    }
  }
  // Grow edge holes (not grazing or empty ones: those are already where they belong).
  std::vector<uint8_t> grown(hole);
  const int r = s.edge_hole_radius_px;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (hole[size_t(y) * width + x] != 2) continue;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < width && yy < height) grown[size_t(yy) * width + xx] = 1;
        }
    }
  ImageU16 out(width, height);
  const uint64_t frame_key = hash_key(hash_key(kDepthNoiseDomain, seed), frame);
  for (size_t i = 0; i < n; ++i) {
    const double z_true = depth_z[i];
    if (grown[i] || z_true < s.min_range_m || z_true > s.max_range_m) continue;
    double z = z_true;
    if (s.axial_noise) z += kinect_axial_sigma(s, z_true) * double(gaussian(hash_key(frame_key, i), 0));
    z = kinect_quantise(s, z);
    const double units = std::round(z * s.depth_scale);
    if (units <= 0.0 || units > 65535.0) continue;
    out.data[i] = uint16_t(units);
  }
  return out;
}

}  // namespace mrgi::reference
