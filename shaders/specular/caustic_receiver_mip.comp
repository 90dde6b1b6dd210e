#version 460
// One box-filtered halving of a caustic receiver map (caustic_receiver.glsl): each texel of
// level k the mean of its four texels of level k - 1 (irradiance, and luminance x distance, so
// the reader's mean distance stays the irradiance-weighted one). The reader takes the level
// whose texels match its pixel's footprint (caustic_receiver_lookup.glsl): a pixel wider than
// the map's texels would otherwise point-sample a caustic's fine structure.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform image2D caustic_receivers;
// xy level k - 1's first texel, zw level k's; in size, x level k's side.
layout(push_constant) uniform Mip { ivec4 origins; ivec4 size; };

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(size.x)))) return;
  ivec2 s = origins.xy + 2 * t;
  vec4 sum = imageLoad(caustic_receivers, s) + imageLoad(caustic_receivers, s + ivec2(1, 0)) +
             imageLoad(caustic_receivers, s + ivec2(0, 1)) + imageLoad(caustic_receivers, s + ivec2(1, 1));
  imageStore(caustic_receivers, origins.zw + t, 0.25f * sum);
}
