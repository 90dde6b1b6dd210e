// LightEstimate -> the shapes apps consume (mrgi/light_estimate.h): ARCore Environmental HDR and
// Filament's pre-scaled irradiance SH.
#include <cmath>

#include "light/sh_tools.h"
#include "mrgi/light_estimate.h"

namespace mrgi {
namespace {

// (A_l / pi) * K_lm * sign for the 9 coefficients of bands 0..2 (Sloan's basis constants of
// shaders/shared/mrgi_shared.h sh_basis16 with their signs; A_l / pi = 1, 2/3, 1/4).
constexpr double kFilamentFactors[9] = {
    0.282094791773878,             -0.488602511902920 * 2.0 / 3.0, 0.488602511902920 * 2.0 / 3.0,
    -0.488602511902920 * 2.0 / 3.0, 1.092548430592079 / 4.0,       -1.092548430592079 / 4.0,
    0.315391565252520 / 4.0,       -1.092548430592079 / 4.0,       0.546274215296040 / 4.0};

// Direction of texel (u, v) of cube face `face` (OpenGL cube map conventions, centre sampling).
std::array<float, 3> cube_direction(int face, int u, int v, int size) {
  const float s = 2.0f * (float(u) + 0.5f) / float(size) - 1.0f;
  const float t = 2.0f * (float(v) + 0.5f) / float(size) - 1.0f;
  switch (face) {
    case 0: return {1.0f, -t, -s};
    case 1: return {-1.0f, -t, s};
    case 2: return {s, 1.0f, t};
    case 3: return {s, -1.0f, -t};
    case 4: return {s, -t, 1.0f};
    default: return {-s, -t, -1.0f};
  }
}

}  // namespace

Expected<EnvironmentalHdr> to_environmental_hdr(const LightEstimate& e, int face_size, float min_confidence) {
  if (face_size < 0 || face_size > 256)
    return fail(ErrorKind::BadUsage, "to_environmental_hdr: face_size " + std::to_string(face_size) +
                                         " outside 0..256 (0 = no cubemap)");
  if (!(min_confidence >= 0.0f && min_confidence <= 1.0f))
    return fail(ErrorKind::BadUsage, "to_environmental_hdr: min_confidence " + std::to_string(min_confidence) +
                                         " outside 0..1");
  EnvironmentalHdr out;
  out.valid = e.valid && e.confidence >= min_confidence;
  out.main_light_direction = e.direction_to_light;
  out.main_light_intensity = e.dominant_intensity;
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c) out.ambient_sh[size_t(3 * i + c)] = e.sh_radiance[size_t(i)][size_t(c)];
  out.face_size = face_size;
  if (face_size == 0) return out;
  light::ShRgb l{};
  for (int i = 0; i < light::kMaxShCoeffs; ++i)
    l[size_t(i)] = glm::dvec3(e.sh_radiance[size_t(i)][0], e.sh_radiance[size_t(i)][1], e.sh_radiance[size_t(i)][2]);
  for (int f = 0; f < 6; ++f) {
    ImageRGBF& img = out.cubemap[size_t(f)];
    img = ImageRGBF(face_size, face_size);
    for (int v = 0; v < face_size; ++v)
      for (int u = 0; u < face_size; ++u) {
        const auto d = cube_direction(f, u, v, face_size);
        const glm::dvec3 r = glm::max(light::sh_evaluate(l, glm::vec3(d[0], d[1], d[2])), glm::dvec3(0.0));
        float* t = img.at(u, v);
        t[0] = float(r.x), t[1] = float(r.y), t[2] = float(r.z);
      }
  }
  return out;
}

std::array<Rgb, 9> to_filament_irradiance(const LightEstimate& e) {
  std::array<Rgb, 9> out{};
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c)
      out[size_t(i)][size_t(c)] = float(kFilamentFactors[i] * double(e.sh_radiance[size_t(i)][size_t(c)]));
  return out;
}

}  // namespace mrgi
