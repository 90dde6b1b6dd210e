// The `baseline` technique: direct light only, as most AR apps ship (DESIGN.md "Techniques"),
// with the DIR paper's real/virtual shadow-map pair per real lamp (no double shadows, eq. 1-5).
// No indirect light. With an environment in scene.json a constant ambient from its mean radiance
// is added (runtime/, FrameConstants::ambient_*), without occlusion.
//
// Quality ladder (best first):
//   level  name     shadow_map_size  internal_scale  pcf_radius
//   0      high     2048             1.0             1  (3x3 bilinear compare taps)
//   1      medium   1024             1.0             1
//   2      low       512             0.75            1
//   3      lowest    256             0.5             0  (1 bilinear compare tap)
// Units: shadow_map_size in texels per side of each map face; internal_scale as a fraction of
// the output width and height; pcf_radius in taps on each side of the centre tap.
// Maps are allocated at 2048 for every lamp at start-up; lower levels render into and read the
// top-left corner, so set_level never allocates.
#pragma once
#include <memory>
#include <vector>

#include "technique/technique.h"

namespace mrgi::technique {

std::vector<QualityLevel> baseline_ladder();
Expected<std::unique_ptr<Technique>> create_baseline(const SharedResources& shared);

}  // namespace mrgi::technique
