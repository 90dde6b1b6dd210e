// Turns a scene description into reference-renderer scenes: generated shapes, glTF content,
// lamps and environment are loaded once; virtual objects are placed per frame time.
#pragma once
#include <vector>

#include "mrgi/reference/description.h"
#include "mrgi/reference/path_tracer.h"
#include "mrgi/scene.h"

namespace mrgi::reference {

class SynthScene {
 public:
  static Expected<SynthScene> load(const SceneDescription& description);

  // The full scene (real and virtual parts) with virtual objects placed at time t (seconds).
  RefScene at_time(double t) const;
  // Frame-0 placement of virtual object i, for scene.json.
  Placement virtual_placement(size_t i, double t) const;
  const ImageRGBF& environment_image() const { return real_.environment.image; }

 private:
  const SceneDescription* description_ = nullptr;
  RefScene real_;                        // real meshes, lamps (real and virtual), environment
  std::vector<RefMesh> virtual_local_;   // virtual meshes in object space (scale applied later)
  std::vector<size_t> virtual_owner_;    // virtual_local_[k] belongs to virtual object owner[k]
};

}  // namespace mrgi::reference
