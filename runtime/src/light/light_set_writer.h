// The light stage's lighting as the shading passes' LightSet (shaders/common/light_set.glsl),
// for techniques whose shading draws no shadow-map layers of its own (dlpv's merge, dvct's
// cones): every lamp with layers -1, the real + virtual and the real ambient as irradiance
// matrices. Baseline writes its own, with its shadow maps' layers.
#pragma once
#include "common/light_set.glsl"
#include "light/light_stage.h"

namespace mrgi::light {

void write_unshadowed_light_set(const light::Lighting& lighting, shader::LightSet& set);

}  // namespace mrgi::light
