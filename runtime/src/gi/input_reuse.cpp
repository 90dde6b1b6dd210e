#include "gi/input_reuse.h"

#include <algorithm>
#include <cmath>

namespace mrgi::gi {
namespace {

constexpr double kPoseM = 1e-3, kPoseDeg = 0.1;
constexpr double kDepthMeanM = 2e-3, kDepthValidity = 0.005;
constexpr float kLampM = 1e-3f, kLampDeg = 0.5f, kLampColour = 0.01f;

bool lamp_close(const LightDesc& a, const LightDesc& b) {
  if (a.type != b.type || a.real != b.real) return false;
  const float cos_tol = std::cos(glm::radians(kLampDeg));
  const glm::vec3 ca = a.color * a.intensity, cb = b.color * b.intensity;
  const float colour_scale = std::max({std::abs(ca.x), std::abs(ca.y), std::abs(ca.z), 1e-30f});
  return glm::length(a.position - b.position) <= kLampM &&
         glm::dot(glm::normalize(a.direction), glm::normalize(b.direction)) >= cos_tol &&
         glm::length(ca - cb) <= kLampColour * colour_scale &&
         std::abs(a.inner_angle_deg - b.inner_angle_deg) <= kLampDeg &&
         std::abs(a.outer_angle_deg - b.outer_angle_deg) <= kLampDeg;
}

bool pose_close(const glm::dmat4& a, const glm::dmat4& b) {
  if (glm::length(glm::dvec3(a[3]) - glm::dvec3(b[3])) > kPoseM) return false;
  const glm::dmat3 r = glm::transpose(glm::dmat3(a)) * glm::dmat3(b);
  const double cos_angle = std::clamp((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cos_angle) <= glm::radians(kPoseDeg);
}

}  // namespace

void InputReuse::reserve(size_t depth_pixels, double depth_scale) {
  source_depth_.assign(depth_pixels, 0);
  depth_scale_ = depth_scale > 0.0 ? depth_scale : 5000.0;
}

void InputReuse::set_frame(int level, const glm::dmat4& camera_to_world, const frame::CameraView* camera,
                           uint64_t objects_revision) {
  now_ = Source{};
  now_.level = level;
  now_.pose = camera_to_world;
  now_.objects = objects_revision;
  depth_ = camera ? camera->depth : frame::DepthView{};
}

void InputReuse::add_lamp(const LightDesc& lamp) {
  if (now_.lamp_count < kMaxLamps) now_.lamps[now_.lamp_count++] = lamp;
}

bool InputReuse::depth_close() const {
  if (depth_.empty() || depth_.size() != source_depth_.size()) return false;
  const double metres_per_unit = 1.0 / depth_scale_;
  double sum_m = 0.0;
  size_t both = 0, changed_validity = 0;
  const uint16_t* now = depth_.data;
  for (size_t i = 0; i < source_depth_.size(); ++i) {
    const bool a = source_depth_[i] != 0, b = now[i] != 0;
    if (a != b) {
      ++changed_validity;
    } else if (a) {
      sum_m += std::abs(double(now[i]) - double(source_depth_[i])) * metres_per_unit;
      ++both;
    }
  }
  const double n = double(std::max<size_t>(source_depth_.size(), 1));
  return double(changed_validity) <= kDepthValidity * n && (both == 0 || sum_m / double(both) <= kDepthMeanM);
}

bool InputReuse::close() const {
  if (!source_.valid || source_.level != now_.level || source_.objects != now_.objects ||
      source_.lamp_count != now_.lamp_count ||
      !pose_close(source_.pose, now_.pose) || !depth_close())
    return false;
  for (size_t i = 0; i < now_.lamp_count; ++i)
    if (!lamp_close(source_.lamps[i], now_.lamps[i])) return false;
  return true;
}

void InputReuse::remember() {
  source_ = now_;
  source_.valid = !depth_.empty() && depth_.size() == source_depth_.size();
  if (source_.valid) std::copy(depth_.data, depth_.data + depth_.size(), source_depth_.begin());
  depth_ = frame::DepthView{};  // the view's memory is the frame's: not kept past it
}

}  // namespace mrgi::gi
