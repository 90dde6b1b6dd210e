// Sensor models of the synthetic capture generator: what a colour camera and a Kinect-like depth
// camera would record of the path-traced scene.
//
// Colour camera. The linear sensor value is x = L * exposure (capture.json `exposure`), the same
// camera_response() the runtime composes with (shaders/shared/mrgi_shared.h): clip to [0, 1], sRGB
// curve, 8-bit rounding. Optional noise before clipping, in units of the full-well capacity:
//   photon shot noise  sigma = sqrt(x / full_well)   (Poisson, Gaussian approximation)
//   read noise         sigma = read_noise / full_well
// (the standard linear sensor model, e.g. EMVA 1288 release 3.1, section 2). The noise
// realisation is a function of (seed, frame, pixel, channel) only, so the camera frame C and the
// reference G of one frame carry the same noise and G - C is the virtual objects' effect alone.
//
// Depth camera (Microsoft Kinect v1 structured light):
//  * Range: true depth < min_range_m or > max_range_m gives 0 (no measurement); 0.4 .. 4 m is the
//    operating range of the device's depth mode (Khoshelham & Oude Elberink 2012, section 1).
//  * Holes at depth edges, where a 4-neighbour's true depth differs by more than edge_jump_m,
//    grown by edge_hole_radius_px (the projector/camera baseline occludes the pattern there), and
//    at grazing incidence, angle between the ray and the surface normal > grazing_limit_deg
//    (the pattern is smeared; Nguyen, Izadi & Lovell 2012, fig. 6, noise diverges above ~70 deg).
//  * Axial noise: Gaussian with sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 metres (Nguyen, Izadi &
//    Lovell 2012, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and Tracking",
//    3DIMPVT, eq. 6, for angles below 60 deg).
//  * Quantisation in the disparity domain: d = f b / z, rounded to 1/8 pixel, z = f b / d, with
//    baseline b = 0.075 m and focal length f = 580 px (Khoshelham & Oude Elberink 2012, "Accuracy
//    and Resolution of Kinect Depth Data for Indoor Mapping Applications", Sensors 12(2),
//    sections 2.2 and 4: the depth resolution grows with z^2).
//  * Encoding: round(z * depth_scale) in a 16-bit PNG (TUM convention: 5000 units per metre).
#pragma once
#include <cstdint>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/image.h"

namespace mrgi::reference {

struct CameraNoiseSettings {
  double full_well_electrons = 0.0;  // 0 = noise off; a typical small-pixel sensor: 5000 .. 20000
  double read_noise_electrons = 0.0; // typical 2 .. 10
};

struct DepthSensorSettings {
  double depth_scale = 5000.0;       // units per metre in the PNG (TUM 5000, OpenNI 1000)
  double min_range_m = 0.4;
  double max_range_m = 4.0;
  double baseline_m = 0.075;
  double focal_px = 580.0;
  double disparity_step_px = 0.125;  // 1/8 pixel sub-pixel disparity steps; 0 = no quantisation
  bool axial_noise = true;
  double noise_a_m = 0.0012, noise_b_per_m = 0.0019, noise_z0_m = 0.4;  // sigma = a + b (z - z0)^2
  double edge_jump_m = 0.05;         // neighbour depth jump that makes a hole; <= 0 = no edge holes
  int edge_hole_radius_px = 1;       // holes grown this many pixels around an edge
  double grazing_limit_deg = 75.0;   // incidence angle above which no depth is measured
};

// Camera frame from linear radiance. `seed` and `frame` key the noise realisation.
Expected<ImageRGB8> camera_frame(const ImageRGBF& radiance, double exposure, const CameraNoiseSettings& noise,
                                 uint64_t seed, uint64_t frame);

// Kinect-like depth from true depth (metres along the optical axis, 0 = nothing seen) and |cos|
// of the incidence angle per pixel (both width * height, row-major).
Expected<ImageU16> depth_frame(const std::vector<float>& depth_z, const std::vector<float>& cos_incidence,
                               int width, int height, const DepthSensorSettings& settings, uint64_t seed,
                               uint64_t frame);

// Axial noise standard deviation at depth z (metres), the model above.
double kinect_axial_sigma(const DepthSensorSettings& settings, double z);
// The depth the quantiser returns for depth z (metres), without noise.
double kinect_quantise(const DepthSensorSettings& settings, double z);

}  // namespace mrgi::reference
