// Whether a virtual fragment is hidden by the real surface seen at its pixel: the one occlusion
// test of the virtual G-buffer (virtual.frag, at the internal resolution) and of the output
// coverage (virtual_coverage.frag, at the output resolution), so the mask compose shows and the
// G-buffer the techniques shade never disagree on what is in front.
//   pixel: the fragment's pixel (integer coordinates: OpenCV pixel centres), k: the raster's
//   pinhole intrinsics, view_z: the fragment's camera-space depth, real_texels_per_pixel: texels
//   of real_position per raster pixel along x and y (1 / step at the internal resolution; internal / output,
//   possibly fractional, at the output's), tolerance: the virtual-behind-real tolerance
//   (FrameConstants::camera.z, a fraction of the depth).
#ifndef MRGI_HIDDEN_BY_REAL_GLSL
#define MRGI_HIDDEN_BY_REAL_GLSL

bool hidden_by_real(sampler2D real_position, sampler2D real_normal, ivec2 pixel, vec4 k,
                    mat3x4 to_camera, float view_z, vec2 real_texels_per_pixel, float tolerance) {
  // The texel whose footprint holds the pixel's centre (for an integer step s, pixel / s).
  ivec2 texel = ivec2((vec2(pixel) + 0.5f) * real_texels_per_pixel);
  vec4 real = texelFetch(real_position, texel, 0);
  if (min(real_texels_per_pixel.x, real_texels_per_pixel.y) < 0.999f && real.w > 0.0f) {
    // A texel coarser than the pixel: the depth of its tangent plane on this pixel's ray (exact
    // on planes, so a virtual object resting on a sloped real surface is not cut by the
    // texel-centre depth).
    mat4 world_to_camera = mat4(transpose(to_camera));
    world_to_camera[3][3] = 1.0f;
    vec3 ray = unproject_pinhole(vec2(pixel), 1.0f, k);
    vec3 p = (world_to_camera * vec4(real.xyz, 1.0f)).xyz;
    vec3 n = mat3(world_to_camera) * texelFetch(real_normal, texel, 0).xyz;
    real.w = tangent_plane_depth(ray, p, n, MRGI_DEPTH_EDGE_RELATIVE);
  }
  // Hidden when a valid real surface is in front by more than the tolerance (a fraction of
  // the depth: sensor noise grows with distance; objects resting on a real surface stay seen).
  return real.w > 0.0f && real.w < view_z * (1.0f - tolerance);
}

#endif
