// A tiny analytic RGB-D scene for the technique tests, built in code so every expected value
// is known: a camera 2 m above a floor looking straight down, a real box on the floor, a real
// spot lamp to the side, a uniform real environment (ambient), and virtual boxes from a glTF
// cube written by the test. The "camera image" is rendered with the same light model the
// baseline uses (Lambert, inverse square, spot cone, constant ambient, hard shadows of the real
// box), so the tests check the implementation rather than the model.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mrgi/frame.h"
#include "mrgi/runtime.h"
#include "mrgi/scene.h"

namespace mrgi::test {

struct Box {
  glm::vec3 lo, hi;
  // Ray p + t d, t in (t_min, t_max): nearest entry t, or nothing.
  std::optional<float> hit(const glm::vec3& p, const glm::vec3& d, float t_min, float t_max) const;
  glm::vec3 normal_at(const glm::vec3& q) const;  // outward normal of the face q lies on
};

enum class SurfaceKind { None, Floor, RealBox, Virtual };

struct SurfaceHit {
  SurfaceKind kind = SurfaceKind::None;
  glm::vec3 point{0.0f}, normal{0.0f};
  float depth = 0.0f;  // along the optical axis, metres
  int virtual_index = -1;
};

struct SyntheticScene {
  Intrinsics intrinsics;        // 64 x 48
  Pose pose;                    // camera 2 m above the origin, looking down (-y)
  double depth_scale = 5000.0;
  double exposure = 1.0;
  float floor_albedo = 0.6f, box_albedo = 0.4f;
  glm::vec3 virtual_base{0.8f, 0.2f, 0.2f};
  Box real_box;
  std::vector<Box> virtual_boxes;  // world AABBs of the placed glTF cubes
  LightDesc lamp;                  // real spot
  float ambient = 0.05f;           // uniform environment radiance
  SceneDesc scene;                 // what the runtime gets (glTF + env files in `folder`)

  // Writes the glTF cube and the environment image into `folder`.
  // `emission`: the cubes' glTF emissiveFactor (radiance; 0 = none).
  // `base`: the cubes' glTF baseColorFactor (black: they only block light); `metallic`,
  // `roughness`: their glTF factors (the default is diffuse); `transmission`: their
  // KHR_materials_transmission factor (> 0: glass).
  static SyntheticScene create(const std::string& folder, const glm::vec3& emission = glm::vec3(0.0f),
                               const glm::vec3& base = glm::vec3(0.8f, 0.2f, 0.2f), float metallic = 0.0f,
                               float roughness = 1.0f, float transmission = 0.0f);
  CameraSetup cameras() const;

  // First surface a camera ray through pixel (u, v) hits; `with_virtual` includes the virtual boxes.
  SurfaceHit trace(int u, int v, bool with_virtual) const;
  // Direct light of the lamp at p with normal n (no shadows), W/m^2/sr per unit albedo x pi.
  float direct(const glm::vec3& p, const glm::vec3& n) const;
  // Whether the segment p -> lamp is blocked by the real box's top face (what the depth camera
  // sees of it), or by any virtual box.
  bool blocked_by_real_top(const glm::vec3& p) const;
  bool blocked_by_virtual(const glm::vec3& p) const;
  bool blocked_by_real(const glm::vec3& p) const;  // the whole real box

  // The camera frame: colour as the camera sees the real scene, depth of the real scene.
  InputFrame frame(int64_t index) const;
};

// `frames` frames of `scene` through a runtime made with `settings` and flushed: every output, in
// order (fewer where a call failed, which is reported as a test failure).
std::vector<FrameOutput> run_synthetic_frames(const SyntheticScene& scene, const RuntimeSettings& settings, int frames);

// `frames` frames of `scene` through `r`, `before(k)` (if given) called before frame k is given,
// flushed: every output in order (fewer where a call failed, reported as a test failure).
std::vector<FrameOutput> run_frames(Runtime& r, const SyntheticScene& scene, int frames,
                                    const std::function<void(int)>& before = {});

// A runtime of `technique` at its cheapest level for `scene`, the other settings `base`'s (null,
// with a test failure, when it cannot be made).
std::unique_ptr<Runtime> cheapest_runtime(const std::string& technique, const SyntheticScene& scene,
                                          const RuntimeSettings& base = {});

// Intersection over union of the output's virtual mask and the pixels the analytic scene sees
// the virtual boxes at. At 64 x 48 a box is a few pixels across and the cheap levels draw it at a
// fraction of that, so its edge pixels disagree: 0.85-0.9 where it is, far less where it is not.
double mask_iou(const FrameOutput& out, const SyntheticScene& scene);

}  // namespace mrgi::test
