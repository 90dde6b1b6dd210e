// Spherical-harmonics helpers of the light stage (and of every technique that projects or reads
// SH light) on the CPU side, on the basis of
// shaders/shared/mrgi_shared.h (sh_basis16: real, orthonormal, Sloan order) so that what the
// shaders project and what the CPU solves and exports agree coefficient for coefficient.
#pragma once
#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mrgi/light_estimate.h"

namespace mrgi::light {

constexpr double kPi = 3.14159265358979323846;
// Rec. 709 luminance of linear RGB, in double for the host-side solves (the shaders' float one is
// mrgi_shared.h `luminance`).
inline double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

constexpr int kMaxShBands = 4;
constexpr int kMaxShCoeffs = kMaxShBands * kMaxShBands;  // 16

using ShVector = std::array<float, kMaxShCoeffs>;           // one channel
using ShRgb = std::array<glm::dvec3, kMaxShCoeffs>;         // linear RGB per coefficient
using ShMatrix = std::array<double, kMaxShCoeffs * kMaxShCoeffs>;  // row-major, a linear map of SH

// Y_i(d) for i < 16 (d is normalised here; a zero vector gives all zeros).
ShVector sh_basis(const glm::vec3& direction);
// Band of coefficient i (l with l*l <= i < (l+1)*(l+1)).
int sh_band(int coefficient);

// Radiance SH of a directional light arriving FROM `direction_to_light` with irradiance
// `irradiance` at normal incidence: L_i = E * Y_i(d), truncated to `bands`.
ShRgb sh_directional_light(const glm::dvec3& direction_to_light, const glm::dvec3& irradiance,
                           int bands = kMaxShBands);

// Radiance arriving from direction d under SH light l: sum_i l_i Y_i(d).
glm::dvec3 sh_evaluate(const ShRgb& l, const glm::vec3& direction);

// Irradiance at a unit normal for radiance SH `l` (no visibility), bands 0..2 exact
// (Ramamoorthi & Hanrahan: band 3 of the clamped cosine is 0).
glm::dvec3 sh_irradiance(const ShRgb& l, const glm::vec3& normal);

// Unit direction towards the dominant light from band 1 of the luminance of `l` (paper Sec.
// 5.4: "the second, third and fourth SH coefficient of l"). Returns false (and leaves `out`)
// when band 1 is zero or not finite, i.e. the light has no dominant direction.
bool sh_dominant_direction(const ShRgb& l, glm::dvec3& out);

// Irradiance at normal incidence (RGB, >= 0) of the directional light from `direction` that best
// reproduces bands 1..2 of the irradiance of `l`, least squares weighted by the cosine lobe:
// C = sum A_l^2 L_lm Y_lm(d) / sum A_l^2 Y_lm(d)^2 over l = 1, 2. A pure directional light is
// recovered exactly.
glm::dvec3 sh_dominant_intensity(const ShRgb& l, const glm::dvec3& direction);

// Fills the exported form (radiance SH, irradiance SH9, dominant light) from `l`.
void fill_light_estimate(const ShRgb& l, int bands, LightEstimate& out);

bool is_finite(const ShRgb& l);

// The k-th of `count` directions spread evenly over the unit sphere (a spherical Fibonacci
// spiral, y from +1 to -1, no jitter): quadrature over the sphere with weight 4 pi / count each.
glm::dvec3 fibonacci_direction(int k, int count);

}  // namespace mrgi::light
