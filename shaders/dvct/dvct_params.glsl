// Push constants of dvct's shading passes (technique/dvct/dvct.h), shared by indirect.comp and
// shade.comp and by the C++ that fills them (like frame_constants.glsl).
#ifndef MRGI_DVCT_PARAMS_GLSL
#define MRGI_DVCT_PARAMS_GLSL
#ifdef __cplusplus
#include <glm/glm.hpp>
namespace mrgi::shader {
using glm::ivec4;
using glm::vec4;
#endif

struct DvctParams {
  vec4 volume;   // xyz: the volumes' min corner (m); w: voxel size (m)
  vec4 trace;    // x: voxels per side used; y: the coarsest mip level; z: occlusion floor
                 // (vct_directional_occlusion); w: step scale (vct_step)
  vec4 cones;    // x: shadow cone aperture (rad); y: narrowest specular cone (rad); z: the
                 // diffuse and specular cones' reach (m); w: roughness at and above which no
                 // specular cone is traced (the diffuse cones hold that light)
  ivec4 mode;    // x: G-buffer pixels per indirect texel (indirect.comp); y: 1 the volumes hold
                 // this frame's light (0: no virtual object or lamp: nothing changes); z: the
                 // environment occlusion's divisor (shade.comp; 0: none this frame); w: 1 the
                 // specular cone sees the objects' own light volume (their ambient and emission)
  vec4 texture;  // x: voxels per side allocated (a cheaper level uses a corner of each mip
                 // level: texture coordinates divide by this); y: the environment grid's width
                 // (EnvCells, common/env_grid.glsl; 0: none, the ambient's irradiance stands in);
                 // z: its pyramid's levels; w unused
};

// The real material regions (scene.json real_materials, mrgi/scene.h RealMaterialRegion): a real
// pixel whose position is in box i takes its roughness and metallic; the first box wins.
#define DVCT_MAX_REAL_MATERIALS 16
struct DvctRealMaterials {
  ivec4 count;                                      // x: boxes in use
  vec4 min_roughness[DVCT_MAX_REAL_MATERIALS];      // xyz: box min (m); w: roughness
  vec4 max_metallic[DVCT_MAX_REAL_MATERIALS];       // xyz: box max (m); w: metallic
};

#ifdef __cplusplus
static_assert(sizeof(DvctParams) == 80, "std430 push constant mirror");
}  // namespace mrgi::shader
#endif
#endif  // MRGI_DVCT_PARAMS_GLSL
