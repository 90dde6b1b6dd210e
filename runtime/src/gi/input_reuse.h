// Whether work made from one frame's inputs (reflective shadow maps, VPLs, ISMs, propagated
// volumes) may stand for another frame's: the skip "inputs unchanged -> reuse the last volumes,
// VPLs or transfer" of docs/DESIGN.md, shared by dlpv and dir. What the work depends on is the level,
// the camera pose (the reconstruction is a function of depth and pose), the depth frame and the
// lamps it was made for; each must stay within the stated tolerance of the frame that made it:
//   - the same level;
//   - the camera pose within 1 mm and 0.1 degrees;
//   - the depth frame within 2 mm mean absolute change over the pixels valid in both, with at
//     most 0.5 % of pixels gaining or losing a depth;
//   - every lamp within 1 mm, 0.5 degrees (direction and cone) and 1 % of its colour x intensity;
//   - the virtual objects where they were (SceneGpu::revision: any move counts; an object that
//     moves, moves every frame, and a tolerance would only delay its light by frames).
// The depth frame is the host's view of the camera (frame/camera_view.h): for frames given as
// the app's images an earlier one (frames_in_flight frames earlier in a steady stream), so a
// change of the depth is seen that many frames late (the pose and the lamps are this frame's). The depth copy is sized at
// reserve() (no allocation per frame).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "frame/camera_view.h"
#include "light/light_stage.h"
#include "mrgi/frame.h"
#include "mrgi/scene.h"

namespace mrgi::gi {

class InputReuse {
 public:
  // `depth_pixels`: the depth camera's width x height; `depth_scale`: its units per metre.
  void reserve(size_t depth_pixels, double depth_scale);
  // This frame's inputs, to compare with the remembered ones (set before close() / remember()).
  void set_frame(int level, const glm::dmat4& camera_to_world, const frame::CameraView* camera,
                 uint64_t objects_revision);
  // The lamps the work is made for this frame (strongest first); at most kMaxLamps are compared.
  void add_lamp(const LightDesc& lamp);
  // Whether the remembered frame's work stands for this one.
  bool close() const;
  // This frame's inputs become the remembered ones (kept only when its depth frame can be
  // compared with the next one's).
  void remember();
  void forget() { source_.valid = false; }
  size_t lamp_count() const { return now_.lamp_count; }

  // The stage's lamps and up to 16 environment regions (dir's environment VPLs).
  static constexpr size_t kMaxLamps = light::kMaxStageLights + 16;

 private:
  struct Source {
    bool valid = false;
    int level = -1;
    glm::dmat4 pose{1.0};
    uint64_t objects = 0;
    std::array<LightDesc, kMaxLamps> lamps{};
    size_t lamp_count = 0;
  };
  bool depth_close() const;
  Source source_, now_;
  frame::DepthView depth_;  // this frame's (a copy of the view: set_frame's may not outlive it)
  std::vector<uint16_t> source_depth_;
  double depth_scale_ = 5000.0;
};

}  // namespace mrgi::gi
