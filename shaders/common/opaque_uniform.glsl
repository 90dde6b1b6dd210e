// Compute shaders: a uniform value the driver must not specialise the shader on.
//
// Why: lavapipe in Mesa 22.3 inlines uniform (UBO / push constant) values that bound a loop into
// the shader and compiles that variant when the pipeline is bound, every time it is bound and
// with no cache of variants (lvp_execute.c update_inline_shader_state; lvp_pipeline.c marks
// shaders with such loops must_inline). ssrt_tsdf_fuse's `z < volume.grid.x` made one LLVM
// compile per frame: about one new executable mapping per frame, RSS growing without bound
// (tests/technique/soak_test.cpp), and the compile's time inside the pass. Adding a value the
// compiler cannot prove uniform-only (min(0, workgroup id z), always 0 for 2D dispatches) keeps
// the bound a runtime value, so the pipeline's one compiled shader is used for every dispatch.
// Use it only on the bound of a loop that reads a uniform (measured: `mrgi bench` with the maps
// of the process counted, test RuntimeSoak).
#ifndef MRGI_OPAQUE_UNIFORM_GLSL
#define MRGI_OPAQUE_UNIFORM_GLSL

#define MRGI_OPAQUE_INT(x) ((x) + min(0, int(gl_WorkGroupID.z)))

#endif  // MRGI_OPAQUE_UNIFORM_GLSL
