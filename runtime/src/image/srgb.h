// sRGB transfer curve (IEC 61966-2-1) on the CPU: camera frames are sRGB-encoded, lighting math
// is linear. A 256-entry table makes 8-bit decoding exact and cheap.
#pragma once
#include <array>
#include <cstdint>

namespace mrgi {

float srgb_to_linear(float encoded);   // [0,1] -> [0,1]
float linear_to_srgb(float linear);    // [0,1] -> [0,1]; clamps outside
const std::array<float, 256>& srgb8_to_linear_table();
// Rounds to the nearest 8-bit code after clamping to [0,1].
uint8_t linear_to_srgb8(float linear);

}  // namespace mrgi
