// Per-frame parameters of the ssrt TSDF volume passes (technique/ssrt/volume.cpp writes them,
// shaders/ssrt/tsdf_*.comp read them). Compiled as GLSL (std140) and as C++ (GLM): only vec4 /
// ivec4 / mat4 members.
//
// Storage: one uint per voxel, packHalf2x16(tsdf in [-1, 1], weight in frames); weight 0 = never
// observed (the clear value 0 is exactly that). Voxel (x, y, z) of a level with resolution r is
// entry x + r (y + r z); its centre is origin.xyz + (i + 0.5) origin.w. A level uses the first r^3
// entries of the buffer, which is allocated for the top level. The fuse pass writes it as a
// storage buffer; the passes that only read it see it through an R32_UINT texel view
// (uimageBuffer): lavapipe loads a storage buffer at per-lane addresses lane by lane in a loop
// with a branch per lane, a texel buffer with vector inserts (ray cast 6.5 -> 3.0 ms at the fast
// level on desk_spot). The fuse pass itself kept the storage buffer: its load and store per
// voxel cost 40 % more as an image.

#ifndef MRGI_SSRT_TSDF_VOLUME_GLSL
#define MRGI_SSRT_TSDF_VOLUME_GLSL

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::mat4;
using glm::vec4;
#endif

struct SsrtVolumeParams {
  mat4 world_to_camera;   // this frame's pose (the depth camera is registered to the colour one)
  mat4 camera_to_world;
  vec4 origin;            // xyz world position of the cube's minimum corner, w voxel side (m)
  vec4 tsdf;              // x truncation mu (m), y weight cap (frames), z depth units per metre,
                          // w cube side (m)
  vec4 depth_k;           // depth camera fx, fy, cx, cy (pixels)
  ivec4 grid;             // x voxels per side, y depth width, z depth height, w aux texels/side
};

#ifdef __cplusplus
static_assert(sizeof(SsrtVolumeParams) == 2 * 64 + 4 * 16, "std140 mirror");
}  // namespace mrgi::shader
#endif

#endif  // MRGI_SSRT_TSDF_VOLUME_GLSL
