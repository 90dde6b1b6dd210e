// Per-frame constants shared by every mrgi pass (one uniform buffer, written by the runtime each
// frame). Compiled both as GLSL (std140) and as C++ (GLM), so the layout is written once: only
// vec4 / ivec4 / mat4 members, which have the same size and 16-byte alignment in std140 and GLM.
// (The file is .glsl so the shader build tracks it as a dependency.)
#ifndef MRGI_FRAME_CONSTANTS_GLSL
#define MRGI_FRAME_CONSTANTS_GLSL

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::mat4;
using glm::vec4;
#endif

// MRGI_UNIFORM_COPIES: every compute pass reads its uniform blocks (this one, the others whose
// structs hold no arrays, its push constants) through private copies made on main's first line:
//   layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
//   FrameConstants frame;
//   void main() { frame = frame_ubo; ... }
// Why: lavapipe (Mesa 22.3's gallivm) loads a uniform value with one scalar load only where no
// lane can be inactive, i.e. at the top level of main before any branch, loop or early return
// (lp_bld_nir_soa.c invocation_0_must_be_active); anywhere else it gathers the value lane by
// lane with a bounds check per lane. ssrt_transfer's sample loop held 32 such eight-lane gathers
// per sample, 2/3 of its instructions (found by reading its JIT code): 32 -> 18 ms, frames bit
// for bit the same. Blocks whose structs hold arrays are copied member by member instead (a
// private copy of an array went to per-lane scratch memory). Other drivers see plain copies.

// Depth discontinuity rule used by normals and the real caster mesh: two neighbouring depths
// belong to one surface when |z_a - z_b| <= MRGI_DEPTH_EDGE_RELATIVE * min(z_a, z_b).
#define MRGI_DEPTH_EDGE_RELATIVE 0.05
// Three depths (a triangle of G-buffer pixels) are one surface: all valid, and their spread
// within the rule above (the real caster mesh, the voxelisation of the real scene).
#ifndef __cplusplus
bool mrgi_one_surface(float a, float b, float c) {
  float zmin = min(a, min(b, c));
  float zmax = max(a, max(b, c));
  return zmin > 0.0f && (zmax - zmin) <= MRGI_DEPTH_EDGE_RELATIVE * zmin;
}
#endif

// Sizes are pixels; k vectors are pinhole intrinsics (fx, fy, cx, cy) in pixels, OpenCV
// convention (mrgi_shared.h project_pinhole / unproject_pinhole).
struct FrameConstants {
  mat4 world_to_clip;     // virtual raster at the internal resolution: Vulkan clip, y down, z 0..1
  mat4 camera_to_world;   // this frame's pose
  mat4 world_to_camera;
  vec4 camera_world;      // xyz camera centre in world, w unused
  vec4 internal_k;        // colour camera scaled to the internal (G-buffer) resolution
  vec4 output_k;          // colour camera scaled to the output resolution
  vec4 color_k;           // colour camera as captured
  vec4 depth_k;           // depth camera as captured
  ivec4 internal_output_size;  // internal w, h; output w, h
  ivec4 color_depth_size;      // colour w, h; depth w, h
  vec4 camera;            // x depth units per metre, y exposure (radiance -> linear camera value),
                          // z virtual-behind-real tolerance (fraction of the real depth), w unused
  ivec4 flags;            // x: 1 depth registered to colour (same intrinsics), 0 resampled;
                          // y: 1 the virtual G-buffer holds emission (virtual_emission), 0 none
};

#ifdef __cplusplus
static_assert(sizeof(FrameConstants) == 3 * 64 + 9 * 16, "std140 mirror");
}  // namespace mrgi::shader
#endif

#endif  // MRGI_FRAME_CONSTANTS_GLSL
