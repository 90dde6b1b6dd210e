// Push constants of dir's VPL shading and merge (technique/dir/dir.h), shared by
// shade_vpl.comp, merge_rows.comp and merge_columns.comp.
#ifndef MRGI_DIR_PARAMS_GLSL
#define MRGI_DIR_PARAMS_GLSL

struct DirParams {
  ivec4 vpls;     // x: VPL slots in use; y: ISM side (texels); z: ISM tiles per atlas row;
                  // w: interleave side (4: each pixel of a 4x4 block shades every 16th VPL; 1: all)
  vec4 lighting;  // x: distance clamp (m, vpl_irradiance); y: ISM relative bias; z: ISM bias (m);
                  // w: 1 = virtual pixels skip the real-path VPLs (DirLevel::real_bounce_beside_camera_ambient)
  ivec4 extent;   // x, y: the indirect images' used size; z: G-buffer pixels per indirect texel;
                  // w: the first environment VPL's slot (x: none), shaded at every pixel
};

#endif
