// `mrgi synth --from-renders DIR`: the frames of a capture taken from images another renderer made
// of the same scene description (tools/cycles/render_description.py, Blender Cycles), instead of
// the path tracer, so the capture's sensors (exposure, sRGB, noise, Kinect depth) and storage are
// mrgi's own and only the light transport is independent.
//
// DIR holds per frame f (6 digits) float OpenEXR files at the colour camera's size:
//   f_C.exr       linear radiance of the real scene (L_r)
//   f_G.exr       linear radiance with the virtual objects (L_rv), same random numbers
//   f_depth.exr   metres along the optical axis of the real scene's pixel-centre ray (channel 0);
//                 0 = no hit
//   f_normal.exr  0.5 + 0.5 n, n the unit world-space normal (mrgi axes) at that hit
//   f_mask.exr    channel 0 >= 0.5 where the pixel-centre ray meets a virtual object first
//   f_env.exr     the env camera's image (env_camera.size squared), when the description has one
// Each is refused with "FILE: RULE" when missing, of the wrong size, or holding NaN/Inf.
#pragma once
#include <string>

#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"
#include "mrgi/reference/description.h"
#include "mrgi/reference/path_tracer.h"

namespace mrgi::reference {

struct RenderedFrame {
  RenderOutput render;   // real, combined, virtual_mask, depth_z, cos_incidence
  ImageRGBF env;         // empty when the description has no env camera
};

// Whether DIR holds every file of every frame of D, so a conversion is refused before anything is
// written (BadInput naming the first missing file).
Status check_renders_present(const std::string& dir, const SceneDescription& d);

// Frame F of DIR for description D, whose camera has pose POSE (camera to world, OpenCV axes) at
// that frame: the incidence cosine of the depth sensor's ray is found from the normal image and
// the pixel's ray.
Expected<RenderedFrame> load_rendered_frame(const std::string& dir, int frame, const SceneDescription& d,
                                            const Pose& pose);

}  // namespace mrgi::reference
